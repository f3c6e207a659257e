#!/usr/bin/env bash
# Checks that every C++ source of efdem is formatted as the project's .clang-format asks
# (clang-format 14, Debian 12's `clang-format` package; scripts/install_deps.sh installs it).
# Run by ctest as unit:format, with a self-test (unit:format_detects_unformatted) that plants an
# unformatted file and must see it flagged.
#
# Usage: check_format.sh SOURCE_DIR     exit 0 if every file is formatted, 1 listing the others
#        check_format.sh --self-test    a formatted and an unformatted scratch file
#        To fix: clang-format -i FILE... (from the source tree, so .clang-format is found)
set -euo pipefail

command -v clang-format > /dev/null \
  || { echo "check_format: clang-format not found (apt-get install clang-format)"; exit 1; }

check_tree() {  # check_tree ROOT: prints the unformatted files; status 1 if any
    local root=$1 files=() bad=()
    while IFS= read -r -d '' f; do files+=("$f"); done \
        < <(find "$root" \( -name build -o -name 'build-*' -o -name .git -o -name runs \) -prune \
                 -o -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -print0)
    # One clang-format for all files; it names each file it would change ("FILE:LINE:COL:
    # error: code should be clang-formatted"). Any other failure is reported as it is.
    local out rc=0
    out=$(clang-format --style=file --dry-run --Werror "${files[@]}" 2>&1) || rc=$?
    mapfile -t bad < <(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' <<< "$out" \
                           | sort -u | sed "s|^$root/||")
    if [ $rc -ne 0 ] && [ ${#bad[@]} -eq 0 ]; then
        echo "check_format: clang-format failed (exit $rc):"; echo "$out" | head -20
        return 1
    fi
    if [ ${#bad[@]} -gt 0 ]; then
        echo "check_format: ${#bad[@]} file(s) differ from what clang-format would write:"
        printf '  %s\n' "${bad[@]}"
        echo "fix with: (cd $root && clang-format -i ${bad[*]})"
        return 1
    fi
}

if [ "${1:-}" = "--self-test" ]; then
    here=$(cd "$(dirname "$0")/.." && pwd)
    scratch=$(mktemp -d)
    trap 'rm -rf "$scratch"' EXIT
    cp "$here/.clang-format" "$scratch/"
    printf 'int f(int x) {\n    return x + 1;\n}\n' > "$scratch/good.cpp"
    check_tree "$scratch" > /dev/null || { echo "self-test: a formatted file was flagged"; exit 1; }
    printf 'int   g( int x ){return x+1;}\n' > "$scratch/bad.cpp"
    out=$(check_tree "$scratch") && { echo "self-test: an unformatted file was not flagged"; exit 1; }
    grep -q "bad.cpp" <<< "$out" || { echo "self-test: the report does not name bad.cpp"; exit 1; }
    echo "self-test passed: the unformatted file was flagged, the formatted one was not"
    exit 0
fi

root=${1:?usage: check_format.sh SOURCE_DIR | --self-test}
check_tree "$(cd "$root" && pwd)"
echo "check_format: every C++ source is formatted"
