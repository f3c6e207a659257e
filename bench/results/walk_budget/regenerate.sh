#!/bin/bash
# Regenerates this folder (README.md and the three plots) from the committed direct ensembles and
# CPI runs at U_s = 0.19: bench/walk_budget.py on each, its output kept under its command.
#     bash bench/results/walk_budget/regenerate.sh
set -euo pipefail
cd "$(dirname "$0")/../../.."
out=bench/results/walk_budget
py=/usr/bin/python3
t4=bench/results/tall_study_r4/u0.19
d8=bench/results/adaptive_study_r8/u0.19
w8=bench/results/whole_process/tall_u0.19_r8
# The tall bed at R = 8: every direct ensemble and CPI run whole_process.py has made so far.
directs=$(ls $w8/direct_?.json)
cpis=$(ls $w8/*.json | grep -v -e '/direct_' -e analysis.json || true)
n=$(echo "$directs" | wc -w)
commands=(
  "$py bench/walk_budget.py --directs $t4/direct_a.h5 $t4/direct_b.h5 --cpi $t4/adaptive_tol0.32.h5 $t4/adaptive_tol0.64.h5 $t4/fixed_dt40.h5 --plot $out/tall_u0.19_r4.png --title 'tall bed, U_s = 0.19, R = 4, 400 units'"
  "$py bench/walk_budget.py --directs $d8/direct_a.h5 $d8/direct_b.h5 --cpi $d8/adaptive_tol0.08.h5 $d8/adaptive_tol0.16.h5 $d8/adaptive_tol0.16_members.h5 $d8/adaptive_tol0.32.h5 $d8/fixed_dt40.h5 $d8/fixed_dt80.h5 --healing 10 --window 10 --plot $out/demo_u0.19_r8.png --title 'demo bed, U_s = 0.19, R = 8, 200 units'"
  "$py bench/walk_budget.py --directs $(echo $directs) --cpi $(echo $cpis) --plot $out/tall_u0.19_r8.png --title 'tall bed, U_s = 0.19, R = 8, 600 units ($n directs)'"
)
{
  echo "# The noise model of bench/walk_budget.py on the committed direct ensembles at U_s = 0.19"
  echo
  echo "Made $(date -u +%F) (git $(git rev-parse --short HEAD)) by \`bash $out/regenerate.sh\`; the commands, then what they print:"
  for c in "${commands[@]}"; do
    echo
    echo "    $c"
    echo
    echo '```'
    eval "$c"
    echo '```'
  done
  echo
  for p in demo_u0.19_r8 tall_u0.19_r4 tall_u0.19_r8; do
    echo "![$p]($p.png)"
    echo
  done
} > $out/README.md.part
mv $out/README.md.part $out/README.md
