#include "mpi_driver/ensemble/reference_rows.hpp"

#include <limits>
#include <utility>

#include "coarse/demixing/whole_bed_profile.hpp"

namespace efdem::mpi_driver {

void ReferenceRows::add(Observation& o) {
    if (needs_.top_half) top_.push_back(std::move(o.top));
    if (needs_.whole_bed) bed_.push_back(std::move(o.whole_bed));
}

void ReferenceRows::add_missing() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (needs_.top_half) top_.push_back(Eigen::VectorXd::Constant(m_, nan));
    if (needs_.whole_bed) bed_.push_back(Eigen::VectorXd::Constant(coarse::kWholeBedNodes, nan));
}

void ReferenceRows::gather(const EnsembleLayout& layout) {
    if (needs_.top_half) all_top_ = layout.gather_rows(top_);
    if (needs_.whole_bed) all_bed_ = layout.gather_rows(bed_);
}

const Eigen::MatrixXd& ReferenceRows::rows(coarse::ReferenceIcdf kind) const {
    switch (kind) {
        case coarse::ReferenceIcdf::top_half:
            return all_top_;
        case coarse::ReferenceIcdf::whole_bed:
            return all_bed_;
        case coarse::ReferenceIcdf::none:
            break;
    }
    return none_;
}

}  // namespace efdem::mpi_driver
