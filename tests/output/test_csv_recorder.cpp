// The run's CSV files as a plain CSV reader (pandas.read_csv without options) sees them: the
// first line names the columns, every row has as many fields, no comment lines; what the
// files are and how the run ended is in the sidecar, which a restart's recorder rewrites.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "mpi_driver/output/csv_recorder.hpp"
#include "tests/support/csv_table.hpp"
#include "tests/support/fp_traps.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
using test::slurp;

RunProvenance cpi_provenance() {
    RunProvenance p;
    p.scene_file = "dir/scene \"one\".cfg";  // a quote, escaped in the JSON sidecar
    p.mode = "cpi";
    p.realizations = 2;
    p.p_grid = Eigen::Vector3d(0.1, 0.5, 0.9);
    p.observed_species = "light";
    return p;
}

SampleRecord sample_at(double t) {
    SampleRecord s;
    s.time = t;
    s.mean = Eigen::Vector3d(1.0 + t, 2.0 + t, 3.0 + t);
    return s;
}

bool has_comment_line(const std::filesystem::path& file) {
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("#", 0) == 0) return true;
    return false;
}
}  // namespace

TEST_CASE(
    "the run's CSV files start with their column names and hold only rows, and the sidecar says "
    "how the run ended",
    "[unit][output]") {
    const auto dir = std::filesystem::temp_directory_path() / "efdem_csv_recorder_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto icdf = dir / "run_mean_icdf.csv", steps = dir / "run_cpi_steps.csv",
               meta = dir / "run_csv_meta.json";
    {
        CsvRecorder r(dir, "run", cpi_provenance());
        CHECK(r.files() == std::vector<std::filesystem::path>{icdf, steps, meta});
        CHECK(slurp(meta).find("\n  \"end_status\": \"running\"\n") != std::string::npos);
        r.sample(sample_at(0.0));
        r.sample(sample_at(0.25));
        {
            // A fixed-DT step has NaN period and error estimates, written as "nan" (printing a
            // NaN raises FE_INVALID inside fmt, which the test traps would turn into SIGFPE).
            const test::FpTrapsOff nan_is_data;
            r.coarse_step(coarse::ProjectiveStepRecord{}, LiftRecord{});
        }
        RunSummary end;
        end.end_status = "completed";
        r.finish(end);
    }
    const test::CsvTable t = test::read_csv_table(icdf);
    CHECK(t.header == std::vector<std::string>{"time", "Q(0.1)", "Q(0.5)", "Q(0.9)"});
    REQUIRE(t.rows.size() == 2);
    CHECK(t.ragged_rows() == 0);
    CHECK(t.rows[1] == std::vector<std::string>{"0.25", "1.25", "2.25", "3.25"});
    const test::CsvTable c = test::read_csv_table(steps);
    CHECK(c.header.size() == 18);
    CHECK(c.header.front() == "t_start");
    CHECK(c.header.back() == "accepted");
    CHECK(c.rows.size() == 1);
    CHECK(c.ragged_rows() == 0);  // the empty 'accepted' of a single-step integrator is a field
    CHECK_FALSE(has_comment_line(icdf));
    CHECK_FALSE(has_comment_line(steps));
    // The line scripts/slurm_job.sh looks for, and the scene file name escaped as JSON.
    const std::string sidecar = slurp(meta);
    CHECK(sidecar.find("\n  \"end_status\": \"completed\",\n") != std::string::npos);
    CHECK(sidecar.find("\"scene_file\": \"dir/scene \\\"one\\\".cfg\"") != std::string::npos);
    CHECK(sidecar.find("\"Q(p)\"") != std::string::npos);

    // A restart's recorder appends rows under the same header and marks the run running again.
    {
        CsvRecorder r(dir, "run", cpi_provenance(), true);
        CHECK(slurp(meta).find("\n  \"end_status\": \"running\"\n") != std::string::npos);
        r.sample(sample_at(0.5));
    }
    const test::CsvTable resumed = test::read_csv_table(icdf);
    CHECK(resumed.header == t.header);
    CHECK(resumed.rows.size() == 3);
    CHECK(resumed.ragged_rows() == 0);
    CHECK(test::read_csv_table(steps).rows.size() == 1);
}
