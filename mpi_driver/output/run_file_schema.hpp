#pragma once
/// \file
/// The run file's schema: for every dataset the recorders write, its units, a short name for
/// labels (CF `long_name`), a description and the names of its dimensions. Hdf5Recorder writes
/// them as the attributes `units`, `long_name` and `description` and as HDF5 dimension scales.
///
/// Format 3 (netCDF-4 readable: xarray opens every group with its default engine and with
/// h5netcdf): every dimension is named after its axis, and the axis is a dataset of that name in
/// the same group as the arrays that use it (axis_of()): /samples/time, /samples/p,
/// /samples/realization, /bed/time, ... Axes that several groups use are repeated in each
/// (netCDF cannot see a dimension scale of a sibling group). docs/output.md is this table in
/// prose; tests/scripts/check_run_file.py checks a real run file against the rule. A dataset
/// missing here is a programmer error (contract).

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace efdem::mpi_driver {

struct DatasetDoc {
    std::string_view path;  ///< e.g. "/samples/icdf"
    std::string_view
        units;  ///< "d_p", "sqrt(d_p/g)", "rho_s g d_p", "1" (dimensionless or a count), "text"
    std::string_view long_name;  ///< a few words for a plot's label, e.g. "bed height"
    std::string_view description;
    /// One name per dimension, slowest first, each the name of its axis dataset in the same
    /// group ("time", "realization", "p", "t_start", "coarse_node", "z", "species", ...); empty
    /// for a scalar dataset. An axis names itself: /samples/time has the dimension "time".
    std::vector<std::string_view> dims;
};

/// The entry for `path`. \pre it exists (every dataset the recorders write is in the table).
const DatasetDoc& dataset_doc(std::string_view path);

/// All entries (for docs and tests).
const std::vector<DatasetDoc>& run_file_schema();

/// The axis dataset of dimension `dim` of `dataset`: the dataset `dim` in the same group
/// ("/bed/height", "time" -> "/bed/time").
std::string axis_of(std::string_view dataset, std::string_view dim);

/// Datasets and groups that format 3 renamed (old path, new path): names that were xarray
/// Dataset methods (`mean`). A run file of an older format is renamed on restart.
const std::vector<std::pair<std::string_view, std::string_view>>& renamed_in_format_3();

}  // namespace efdem::mpi_driver
