#!/usr/bin/env bash
# Checks the dependency rule of ARCHITECTURE.md on the #include lines of the sources:
#
#   core                 -> (nothing of efdem; no MPI, no HDF5)
#   dem                  -> core                    (no MPI)
#   coarse (generic)     -> core                    (no DEM, no MPI)
#     equation_free/     -> no coarse/demixing/, coarse/dem_adapters/ (generic numerics), by method:
#       (top: the seam)  -> none of its method folders
#       estimators/      -> the seam only          krylov/     -> the seam only
#       projective/      -> the seam, estimators/, krylov/ (not steady/)
#       steady/          -> the seam, estimators/, krylov/ (not projective/)
#     demixing/          -> no coarse/dem_adapters/
#   coarse/dem_adapters  -> coarse, dem, core       (no MPI)
#   mpi_driver           -> everything, in rooms (one CMake target each; mpi_driver/CMakeLists.txt):
#     parallel/          -> no other mpi_driver/ room; no HDF5 (MPI plumbing only)
#     checkpoint_data/   -> no other mpi_driver/ room; no MPI, no HDF5 (data only)
#     output/            -> no other mpi_driver/ room; no mpi.h (HDF5 brings it)
#     ensemble/          -> parallel/, checkpoint_data/, output/ but not its recorders (samples
#                           leave through output/sample_sink.hpp); no checkpoint/, run/, HDF5
#     checkpoint/        -> parallel/, checkpoint_data/, output/; no ensemble/, run/
#     run/, main.cpp     -> everything above; no HDF5 header of their own (HDF5 only in
#                           output/, checkpoint/)
#
# and, between the rooms of dem/ (one target; dem/CMakeLists.txt):
#
#   contact/ <-/-> gas/                  the two physics rooms know nothing of each other
#   contact/, gas/, body_forces/         -> no beds/, settling/, io/, realization builder
#                                           (forces come before preparing beds and writing)
#   io/                                  -> no contact/, gas/, body_forces/, settling/, effect
#                                           registry, realization builder (it reads a System)
#   top level (scene, System, ...)       -> no beds/, settling/, io/: only realization_builder
#                                           puts them together (no scene <-> beds cycle)
#   settling/                            <- realization_builder.cpp only
#   realization_builder.hpp              <- nothing in dem/ (it is the top)
#   effect headers (body_forces/, contact/{pair,wall}_contact.hpp, gas/gas_drag.hpp)
#                                        <- effect_registry.cpp, settling/ (its damping stage),
#                                           beds/bed_diagnostics.cpp (GasDrag::pressure_drop)
#
# A file including its own header never counts.
#
# The CMake targets enforce the same rule at link time (target_link_libraries); this script
# catches an #include that slips through a transitive include path.
#
# Usage: check_dependencies.sh SOURCE_DIR     exit 0 if the rule holds, 1 with the violations
#        check_dependencies.sh --self-test    plants violations in a scratch tree; must catch each
set -euo pipefail

check_tree() {
    local root=$1 status=0
    # forbid_files FOLDER FILES PATTERN DESCRIPTION [ALLOWED]: no file under FOLDER whose path
    # from the root (dem/scene.cpp) matches the ERE FILES (empty: all) and not the ERE ALLOWED
    # may #include a path matching PATTERN; a file's #include of its own header is skipped.
    forbid_files() {
        local folder=$1 files=$2 pattern=$3 what=$4 allowed=${5:-}
        [ -d "$root/$folder" ] || return 0
        local hits
        hits=$(grep -rnE --include='*.hpp' --include='*.cpp' --include='*.h' \
                 "^[[:space:]]*#[[:space:]]*include[[:space:]]*[<\"]($pattern)" "$root/$folder" \
                 | sed "s|^$root/||" \
                 | awk -v files="$files" -v allowed="$allowed" '{
                       path = substr($0, 1, index($0, ":") - 1)
                       if (path !~ files || (allowed != "" && path ~ allowed)) next
                       own = path; sub(/\.[^.\/]*$/, "", own)
                       if (index($0, "\"" own ".hpp\"") || index($0, "\"" own ".h\"")) next
                       print
                   }' || true)
        if [ -n "$hits" ]; then
            echo "dependency rule violated: $what:"
            echo "$hits" | sed "s|^|  |"
            status=1
        fi
    }
    # forbid FOLDER PATTERN DESCRIPTION [EXCLUDE_SUBDIR]: no file under FOLDER (except under
    # FOLDER/EXCLUDE_SUBDIR) may #include a path matching PATTERN.
    forbid() {
        local folder=$1 exclude=${4:-}
        forbid_files "$folder" '' "$2" "$folder must not include $3" "${exclude:+^$folder/$exclude/}"
    }
    forbid core 'dem/|coarse/|mpi_driver/|mpi\.h|hdf5\.h' "dem/, coarse/, mpi_driver/, MPI or HDF5"
    forbid dem 'coarse/|mpi_driver/|mpi\.h' "coarse/, mpi_driver/ or MPI"
    forbid coarse 'dem/|mpi_driver/|mpi\.h' "dem/, mpi_driver/ or MPI (only coarse/dem_adapters may see dem/)" dem_adapters
    forbid coarse/dem_adapters 'mpi_driver/|mpi\.h' "mpi_driver/ or MPI"
    # The rooms of dem/ (the table at the top).
    forbid dem/contact 'dem/gas/' "dem/gas/ (contact and gas know nothing of each other)"
    forbid dem/gas 'dem/contact/' "dem/contact/ (contact and gas know nothing of each other)"
    local late='dem/(beds|settling|io)/|dem/realization_builder\.hpp'
    forbid dem/contact "$late" "dem/beds/, dem/settling/, dem/io/ or the realization builder"
    forbid dem/gas "$late" "dem/beds/, dem/settling/, dem/io/ or the realization builder"
    forbid dem/body_forces "$late" "dem/beds/, dem/settling/, dem/io/ or the realization builder"
    forbid dem/io 'dem/(contact|gas|effects|settling)/|dem/effect_registry\.hpp|dem/realization_builder\.hpp' \
        "dem/contact/, dem/gas/, dem/body_forces/, dem/settling/, the effect registry or the realization builder"
    forbid_files dem '^dem/[^/]+$' 'dem/(beds|settling|io)/' \
        "the top level of dem/ must not include dem/beds/, dem/settling/ or dem/io/ (only dem/realization_builder.* puts them together)" \
        '^dem/realization_builder\.(hpp|cpp)$'
    forbid_files dem '^dem/' 'dem/settling/' \
        "dem/settling/ is included by dem/realization_builder.cpp only" '^dem/(realization_builder\.cpp|settling/)'
    forbid_files dem '^dem/' 'dem/realization_builder\.hpp' \
        "nothing in dem/ includes dem/realization_builder.hpp (it is the top of dem/)"
    forbid_files dem '^dem/' 'dem/(body_forces/|contact/(pair|wall)_contact\.hpp|gas/gas_drag\.hpp)' \
        "effect headers are included by dem/effect_registry.cpp, dem/settling/ and dem/beds/bed_diagnostics.cpp only (effects are made by name)" \
        '^dem/(effect_registry\.cpp|beds/bed_diagnostics\.cpp)$|^dem/settling/'
    # The rooms of coarse/ and mpi_driver/ (the table at the top).
    forbid coarse/equation_free 'coarse/(demixing|dem_adapters)/' \
        "coarse/demixing/ or coarse/dem_adapters/ (generic equation-free numerics know no demixing)"
    forbid coarse/demixing 'coarse/dem_adapters/' "coarse/dem_adapters/"
    local ef=coarse/equation_free
    forbid_files $ef "^$ef/[^/]+$" "$ef/(projective|estimators|steady|krylov)/" \
        "the seam (the top of $ef/) must not include its method folders"
    forbid $ef/estimators "$ef/(projective|steady|krylov)/" "projective/, steady/ or krylov/ (estimators stand on the seam)"
    forbid $ef/krylov "$ef/(projective|steady|estimators)/" "projective/, steady/ or estimators/ (krylov stands on the seam)"
    forbid $ef/projective "$ef/steady/" "$ef/steady/ (the two methods know nothing of each other)"
    forbid $ef/steady "$ef/projective/" "$ef/projective/ (the two methods know nothing of each other)"
    local md=mpi_driver
    forbid $md/parallel "$md/(checkpoint_data|output|ensemble|checkpoint|run)/|hdf5\\.h|H5[A-Za-z_]*\\.h" \
        "another mpi_driver/ room or HDF5 (MPI plumbing only)"
    forbid $md/checkpoint_data "$md/(parallel|output|ensemble|checkpoint|run)/|mpi\\.h|hdf5\\.h|H5[A-Za-z_]*\\.h" \
        "another mpi_driver/ room, MPI or HDF5 (what a checkpoint holds: data only)"
    forbid $md/output "$md/(parallel|checkpoint_data|ensemble|checkpoint|run)/|mpi\\.h" \
        "another mpi_driver/ room or MPI (recorders only record)"
    forbid $md/ensemble "$md/(checkpoint|run)/|$md/output/(run_recorder|recorder_list|hdf5_recorder|csv_recorder|h5_file|run_file_schema)\\.|hdf5\\.h|H5[A-Za-z_]*\\.h" \
        "mpi_driver/checkpoint/ (I/O), run/, the recorders (samples leave through output/sample_sink.hpp) or HDF5"
    forbid $md/checkpoint "$md/(ensemble|run)/" "mpi_driver/ensemble/ or run/"
    forbid_files mpi_driver '^mpi_driver/(run/|main\.cpp$)' 'hdf5\.h|H5[A-Za-z_]*\.h' \
        "mpi_driver/run/ and main.cpp include no HDF5 header (HDF5 only in output/ and checkpoint/)"
    return $status
}

if [ "${1:-}" = "--self-test" ]; then
    scratch=$(mktemp -d)
    trap 'rm -rf "$scratch"' EXIT
    mkdir -p "$scratch"/{core,dem/{contact,gas,body_forces,beds,settling,io},coarse/{dem_adapters,demixing}} \
             "$scratch"/coarse/equation_free/{projective,estimators,steady,krylov} \
             "$scratch"/mpi_driver/{parallel,checkpoint_data,output,ensemble,checkpoint,run}
    echo '#include "core/vec3.hpp"' > "$scratch/dem/ok.cpp"
    # What the rooms of dem/ may include (the exceptions of the rules must not be flagged).
    printf '#include "dem/%s"\n' realization_builder.hpp settling/settling.hpp beds/bed_builder.hpp \
        io/lammps_data.hpp > "$scratch/dem/realization_builder.cpp"
    printf '#include "dem/%s"\n' settling/settling.hpp beds/bed_builder.hpp body_forces/viscous_damping.hpp \
        effect_registry.hpp > "$scratch/dem/settling/settling.cpp"
    printf '#include "dem/%s"\n' body_forces/gravity.hpp contact/pair_contact.hpp gas/gas_drag.hpp \
        > "$scratch/dem/effect_registry.cpp"
    printf '#include "dem/%s"\n' beds/bed_diagnostics.hpp gas/gas_drag.hpp gas/slab_fields.hpp \
        > "$scratch/dem/beds/bed_diagnostics.cpp"
    printf '#include "dem/%s"\n' body_forces/gravity.hpp effect.hpp > "$scratch/dem/body_forces/gravity.cpp"
    printf '#include "dem/%s"\n' contact/pair_contact.hpp contact/contact_history.hpp neighbor_list.hpp \
        > "$scratch/dem/contact/pair_contact.cpp"
    printf '#include "dem/%s"\n' io/bed_time_series.hpp beds/bed_diagnostics.hpp system.hpp \
        > "$scratch/dem/io/bed_time_series.cpp"
    printf '#include "dem/%s"\n' contact/contact_history.hpp gas/slab_fields.hpp > "$scratch/dem/system.hpp"
    echo '#include "dem/particles.hpp"' > "$scratch/coarse/dem_adapters/ok.cpp"
    echo '#include <mpi.h>' > "$scratch/mpi_driver/ok.cpp"
    echo '#include "coarse/equation_free/coarse_stepper.hpp"' > "$scratch/coarse/demixing/ok.cpp"
    printf '#include "coarse/equation_free/%s"\n' coarse_stepper.hpp estimators/slope_estimators.hpp \
        krylov/gmres.hpp > "$scratch/coarse/equation_free/steady/ok.cpp"
    printf '#include "coarse/equation_free/%s"\n' coarse_stepper.hpp estimators/phase_drift.hpp \
        > "$scratch/coarse/equation_free/projective/ok.cpp"
    # What the rooms of mpi_driver/ may include.
    printf '#include %s\n' '<mpi.h>' '"core/error.hpp"' '"mpi_driver/parallel/mpi_session.hpp"' \
        > "$scratch/mpi_driver/parallel/ensemble_layout.cpp"
    printf '#include "%s"\n' dem/contact/contact_history.hpp coarse/equation_free/projective/projective_run.hpp \
        mpi_driver/checkpoint_data/realization_state.hpp > "$scratch/mpi_driver/checkpoint_data/checkpoint_format.cpp"
    printf '#include "%s"\n' core/vec3.hpp mpi_driver/output/sample_sink.hpp > "$scratch/mpi_driver/output/csv_recorder.cpp"
    printf '#include "%s"\n' mpi_driver/checkpoint_data/checkpoint_format.hpp mpi_driver/checkpoint_data/realization_state.hpp \
        mpi_driver/output/sample_sink.hpp mpi_driver/output/progress.hpp mpi_driver/parallel/ensemble_layout.hpp \
        '<mpi.h>' > "$scratch/mpi_driver/ensemble/ok.cpp"
    printf '#include %s\n' '<hdf5.h>' '"mpi_driver/parallel/ensemble_layout.hpp"' '"mpi_driver/output/h5_file.hpp"' \
        '"mpi_driver/checkpoint_data/checkpoint_format.hpp"' > "$scratch/mpi_driver/checkpoint/checkpoint_writer.cpp"
    echo '#include <hdf5.h>' > "$scratch/mpi_driver/output/h5_file.hpp"
    printf '#include "%s"\n' mpi_driver/checkpoint/checkpoint_writer.hpp mpi_driver/ensemble/ensemble_stepper.hpp \
        mpi_driver/parallel/stop_signal.hpp mpi_driver/output/run_recorder.hpp > "$scratch/mpi_driver/run/driver.cpp"
    check_tree "$scratch" > /dev/null || { echo "self-test: a clean tree was flagged"; exit 1; }
    for bad in "dem/a.cpp:#include <mpi.h>" "dem/b.hpp:#include \"coarse/demixing/quantiles.hpp\"" \
               "coarse/c.cpp:#include \"dem/system.hpp\"" "coarse/d.hpp:  #  include <mpi.h>" \
               "core/e.cpp:#include \"dem/particles.hpp\"" "coarse/dem_adapters/f.cpp:#include <mpi.h>" \
               "dem/contact/g.cpp:#include \"dem/gas/slab_fields.hpp\"" \
               "dem/gas/h.hpp:#include \"dem/contact/contact_laws.hpp\"" \
               "dem/body_forces/i.cpp:#include \"dem/beds/bed_builder.hpp\"" \
               "dem/io/j.cpp:#include \"dem/contact/contact_history.hpp\"" \
               "dem/scene.cpp:#include \"dem/beds/bed_builder.hpp\"" \
               "dem/beds/k.cpp:#include \"dem/settling/settling.hpp\"" \
               "dem/io/l.cpp:#include \"dem/realization_builder.hpp\"" \
               "dem/scene.hpp:#include \"dem/realization_builder.hpp\"" \
               "dem/system.cpp:#include \"dem/contact/pair_contact.hpp\"" \
               "dem/beds/bed_builder.cpp:#include \"dem/body_forces/viscous_damping.hpp\"" \
               "coarse/equation_free/m.cpp:#include \"coarse/demixing/quantiles.hpp\"" \
               "coarse/demixing/n.hpp:#include \"coarse/dem_adapters/apply_colours.hpp\"" \
               "coarse/equation_free/n1.hpp:#include \"coarse/equation_free/projective/projective_run.hpp\"" \
               "coarse/equation_free/estimators/n2.cpp:#include \"coarse/equation_free/projective/cpi_settings.hpp\"" \
               "coarse/equation_free/krylov/n3.cpp:#include \"coarse/equation_free/steady/coarse_map.hpp\"" \
               "coarse/equation_free/projective/n4.cpp:#include \"coarse/equation_free/steady/coarse_map.hpp\"" \
               "coarse/equation_free/steady/n5.cpp:#include \"coarse/equation_free/projective/projective_jump.hpp\"" \
               "mpi_driver/output/o.cpp:#include \"mpi_driver/ensemble/ensemble_stepper.hpp\"" \
               "mpi_driver/output/o2.cpp:#include \"mpi_driver/parallel/ensemble_layout.hpp\"" \
               "mpi_driver/output/p.cpp:#include <mpi.h>" \
               "mpi_driver/parallel/v.cpp:#include \"mpi_driver/ensemble/realization.hpp\"" \
               "mpi_driver/parallel/w.cpp:#include \"mpi_driver/output/progress.hpp\"" \
               "mpi_driver/parallel/w2.hpp:#include <hdf5.h>" \
               "mpi_driver/ensemble/q.cpp:#include <hdf5.h>" \
               "mpi_driver/ensemble/r.cpp:#include \"mpi_driver/checkpoint/checkpoint_writer.hpp\"" \
               "mpi_driver/ensemble/r2.hpp:#include \"mpi_driver/output/run_recorder.hpp\"" \
               "mpi_driver/ensemble/s.cpp:#include \"mpi_driver/run/run_settings.hpp\"" \
               "mpi_driver/checkpoint/t.cpp:#include \"mpi_driver/run/driver.hpp\"" \
               "mpi_driver/checkpoint/t2.cpp:#include \"mpi_driver/ensemble/ensemble_stepper.hpp\"" \
               "mpi_driver/checkpoint_data/checkpoint_format.cpp:#include <H5Fpublic.h>" \
               "mpi_driver/checkpoint_data/x.cpp:#include <mpi.h>" \
               "mpi_driver/checkpoint_data/realization_state.hpp:#include \"mpi_driver/ensemble/realization.hpp\"" \
               "mpi_driver/checkpoint_data/y.hpp:#include \"mpi_driver/parallel/ensemble_layout.hpp\"" \
               "mpi_driver/run/u.cpp:#include <hdf5.h>" \
               "mpi_driver/main.cpp:#include <hdf5.h>"; do
        file=${bad%%:*}; line=${bad#*:}
        echo "$line" > "$scratch/$file"
        if check_tree "$scratch" > /dev/null; then
            echo "self-test: violation not detected: $file: $line"; exit 1
        fi
        rm "$scratch/$file"
    done
    echo "self-test passed: every planted violation was detected"
    exit 0
fi

check_tree "${1:?usage: check_dependencies.sh SOURCE_DIR | --self-test}"
echo "dependency rule holds"
