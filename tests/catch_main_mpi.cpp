// The Catch2 runner for MPI test executables: MPI_Init before the session, MPI_Finalize after.
// Every rank runs every test case; a test checks its collective result on each rank. The
// process exit code is the largest over all ranks, so a failure on any rank fails the run.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <mpi.h>

#include "tests/support/fp_traps.hpp"

int main(int argc, char* argv[]) {
    MPI_Init(&argc, &argv);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    Catch::Session session;
    // Only rank 0 reports on stdout unless asked otherwise; failures print on every rank.
    const int parse = session.applyCommandLine(argc, argv);
    int result = parse;
    if (parse == 0) {
        efdem::test::enable_fp_traps();
        result = session.run();
        efdem::test::disable_fp_traps();
    }
    int worst = 0;
    MPI_Allreduce(&result, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return worst;
}
