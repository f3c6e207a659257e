#pragma once
/// \file
/// The run file's schema: for every dataset the recorders write, its units, a description and
/// the names of its dimensions. Hdf5Recorder writes them as the attributes `units` and
/// `description` and as HDF5 dimension scales (labels on every dimension; the axis datasets
/// attached where one exists), so that h5py, xarray and ParaView see what each array is.
/// docs/output.md is this table in prose; tests/scripts/test_run_file_schema.py checks a
/// real run file against it. A dataset missing here is a programmer error (contract).

#include <string>
#include <string_view>
#include <vector>

namespace efdem::mpi_driver {

struct DatasetDoc {
    std::string_view path;  ///< e.g. "/samples/icdf"
    std::string_view
        units;  ///< "d_p", "sqrt(d_p/g)", "rho_s g d_p", "1" (dimensionless or a count), "text"
    std::string_view description;
    /// One name per dimension, slowest first: "sample", "realization", "node", "step",
    /// "coarse_node", "species", "slab", "failure"; empty for a scalar dataset.
    std::vector<std::string_view> dims;
};

/// The entry for `path`. \pre it exists (every dataset the recorders write is in the table).
const DatasetDoc& dataset_doc(std::string_view path);

/// All entries (for docs and tests).
const std::vector<DatasetDoc>& run_file_schema();

/// The axis dataset of a dimension name ("sample" -> "/samples/time"), or "" where there is
/// none (a dimension then only carries its label).
std::string_view dimension_scale(std::string_view dim);

}  // namespace efdem::mpi_driver
