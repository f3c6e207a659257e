#pragma once
/// \file
/// Collective scene reading: rank 0 reads the scene file and broadcasts its text, so that every
/// rank parses the same bytes and raises the same InputError (also when only rank 0 can see the
/// file, as on clusters whose compute nodes do not share the submit directory).

#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"

namespace efdem::mpi_driver {

/// Reads `path` on rank 0, broadcasts it, parses it on every rank and applies the overrides.
/// Collective. Throws the same InputError on every rank.
ParamTable read_scene(const MpiSession& mpi, const std::string& path,
                      const std::vector<std::string>& overrides);

}  // namespace efdem::mpi_driver
