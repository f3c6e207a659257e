# Run at every build (cmake -P, from core/CMakeLists.txt): writes OUT, a C++ source defining
# efdem::detail::kGitHash = the short hash of SOURCE_DIR's HEAD, with "-dirty" if tracked files
# differ from it, or "unknown" outside a git checkout. The file is rewritten only when its text
# changes, so an unchanged tree rebuilds nothing. (A hash taken at configure time, as before,
# went stale at the first commit after it and was recorded in every output file.)
execute_process(COMMAND git rev-parse --short=12 HEAD WORKING_DIRECTORY ${SOURCE_DIR}
                OUTPUT_VARIABLE hash OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
if(hash)
  execute_process(COMMAND git status --porcelain --untracked-files=no WORKING_DIRECTORY ${SOURCE_DIR}
                  OUTPUT_VARIABLE changes OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(changes)
    string(APPEND hash "-dirty")
  endif()
else()
  set(hash "unknown")
endif()
set(text "// Generated at build time by core/git_hash.cmake: do not edit.\n#include \"core/version.hpp\"\n\nnamespace efdem::detail {\nconst char* const kGitHash = \"${hash}\";\n}  // namespace efdem::detail\n")
set(old "")
if(EXISTS ${OUT})
  file(READ ${OUT} old)
endif()
if(NOT old STREQUAL text)
  file(WRITE ${OUT} "${text}")
endif()
