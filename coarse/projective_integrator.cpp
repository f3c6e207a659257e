#include "coarse/projective_integrator.hpp"

namespace efdem::coarse {

std::string_view to_string(StepStatus status) {
    switch (status) {
        case StepStatus::projected:
            return "projected";
        case StepStatus::burst_only:
            return "burst_only";
        case StepStatus::stopped_unstable:
            return "stopped_unstable";
        case StepStatus::too_few_periods:
            return "too_few_periods";
        case StepStatus::invalid_burst:
            return "invalid_burst";
        case StepStatus::infeasible_projection:
            return "infeasible_projection";
    }
    return "unknown";
}

}  // namespace efdem::coarse
