#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "mpi_driver/output/thermo_screen.hpp"

using efdem::mpi_driver::SampleRecord;
using efdem::mpi_driver::thermo_line;
using efdem::mpi_driver::ThermoScreen;

namespace {
SampleRecord record(double time, const std::vector<std::vector<double>>& rows) {
    SampleRecord s;
    s.time = time;
    s.thermo.resize(static_cast<Eigen::Index>(rows.size()), 4);
    for (std::size_t r = 0; r < rows.size(); ++r)
        for (int c = 0; c < 4; ++c) s.thermo(static_cast<Eigen::Index>(r), c) = rows[r][c];
    return s;
}

std::vector<double> numbers(const std::string& line) {
    std::istringstream in(line);
    std::vector<double> out;
    for (double v; in >> v;) out.push_back(v);
    return out;
}
}  // namespace

TEST_CASE("the ensemble thermo line: means over the realizations in it, the largest overlap",
          "[unit][output]") {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Two measured realizations and one dropped (NaN): the dropped one is not in the line.
    const SampleRecord s =
        record(2.5, {{1.0e-3, 2.0, 1.0e-3, 10}, {nan, nan, nan, nan}, {3.0e-3, 3.0, 4.0e-3, 13}});
    const std::vector<double> v = numbers(thermo_line(s));
    REQUIRE(v.size() == 6);
    // Printed with 4-5 significant digits: the values below are exact in that many.
    CHECK(v[0] == Approx(2.5));
    CHECK(v[1] == Approx(2.0e-3));  // mean KE per particle
    CHECK(v[2] == Approx(2.5));     // mean contacts per particle
    CHECK(v[3] == Approx(4.0e-3));  // the largest overlap, not the mean
    CHECK(v[4] == Approx(11.5));    // mean builds per realization
    CHECK(v[5] == 2);               // realizations in the line
    CHECK(thermo_line(record(1.0, {{nan, nan, nan, nan}})).empty());
}

TEST_CASE("the thermo line comes at the first sample at or after each interval, header once",
          "[unit][output]") {
    ThermoScreen screen(1.0, 2);
    std::vector<double> printed;
    int headers = 0;
    // Samples every 0.25 from 0.25 (a run's first sample), with the rounding of accumulated
    // times; a cpi jump from 2.25 to 3.6 (no sample at 3.0): the line comes at 3.6, then at 4.1,
    // the first sample at or after 4.
    double t = 0.25;
    std::vector<double> times;
    for (int i = 1; i < 10; ++i, t += 0.25) times.push_back(i == 4 ? 1.0 - 1e-13 : t);
    for (double tt : {3.6, 3.85, 4.1, 4.35}) times.push_back(tt);
    for (double time : times) {
        const std::string out = screen.lines_for(record(time, {{1, 1, 0, 0}, {1, 1, 0, 0}}));
        if (out.empty()) continue;
        if (out.find("KinEng/N") != std::string::npos) ++headers;
        printed.push_back(numbers(out.substr(out.rfind('\n') + 1))[0]);
    }
    CHECK(headers == 1);
    REQUIRE(printed.size() == 4);
    CHECK(printed[0] == Approx(1.0));  // 1 - 1e-13 counts as 1; not 0.25, not a multiple
    CHECK(printed[1] == Approx(2.0));
    CHECK(printed[2] == Approx(3.6));
    CHECK(printed[3] == Approx(4.1));
}
