#!/usr/bin/env bash
# Instructions per pose per iteration (issue 18), by callgrind, for one solver
# of the peer comparison, split into the generated residuals (the evaluation)
# and everything else:
#
#   cargo build --release --manifest-path peers/Cargo.toml
#   peers/count_instructions.sh sagcal        # or apex-solver, factrs
#   peers/count_instructions.sh floor         # the evaluation floor (floor-fused: one call per pose)
#
# Four runs of `sagcal-peers --count SOLVER` (poses N1, N2; linearisation
# budgets K1, K2), each counting only `counted_solve` (apex: its `optimize`); the double difference
#   [C(N2,K2) - C(N2,K1) - C(N1,K2) + C(N1,K1)] / ((N2 - N1)(K2 - K1))
# leaves one pose's share of one iteration (graph building, pattern analysis,
# the first linearisation and the dense 16 x 16 work cancel). The floor needs
# no iterations: [C(N2) - C(N1)] / (N2 - N1) inside `counted_floor`.
# "Evaluation" is a second set of runs counting only inside the generated
# functions (`sagcal::generated::*`, with the libm calls they make; apex calls
# them too) or, for factrs, inside its own dual-number residuals
# (`*factrs_peer*residual*`), with the same double difference.
set -euo pipefail
solver=${1:?usage: count_instructions.sh sagcal|apex-solver|factrs|floor|floor-fused}
N1=${N1:-100} N2=${N2:-300} K1=${K1:-1} K2=${K2:-3}
root=$(cd "$(dirname "$0")" && pwd)
binary=${BINARY:-$root/target/release/sagcal-peers}
out=${OUT:-$root/target/callgrind}
mkdir -p "$out"
case $solver in
  factrs) evaluation='*factrs_peer*residual*' ;;
  *) evaluation='sagcal::generated::*' ;;
esac
# apex-solver solves inside a one-thread rayon pool, on another thread than
# `counted_solve`: its region is its `optimize`.
case $solver in
  floor*) region='*counted_floor*' ;;
  apex-solver) region='apex_solver::optimizer::levenberg_marquardt::LevenbergMarquardt::optimize' ;;
  *) region='*counted_solve*' ;;
esac

# instructions FILE REGION N K: the count of one run inside REGION
instructions() {
  valgrind --tool=callgrind --callgrind-out-file="$1" --toggle-collect="$2" \
    "$binary" --count "$solver" --poses "$3" --iterations "$4" >"$1.log" 2>&1 || {
    cat "$1.log" >&2
    exit 1
  }
  callgrind_annotate "$1" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}'
}

# count N K -> "total evaluation"
count() {
  local total evaluation_count
  total=$(instructions "$out/$solver-$1-$2.out" "$region" "$1" "$2")
  evaluation_count=$(instructions "$out/$solver-$1-$2-evaluation.out" "$evaluation" "$1" "$2")
  echo "$total $evaluation_count"
}

if [[ $solver == floor* ]]; then
  read -r t1 e1 < <(count "$N1" 1)
  read -r t2 e2 < <(count "$N2" 1)
  awk -v t1="$t1" -v t2="$t2" -v n1="$N1" -v n2="$N2" -v s="$solver" \
    'BEGIN { printf "%s: %.0f instructions per pose (the generated calls of one linearisation)\n", s, (t2 - t1) / (n2 - n1) }'
  exit 0
fi
read -r t11 e11 < <(count "$N1" "$K1")
read -r t12 e12 < <(count "$N1" "$K2")
read -r t21 e21 < <(count "$N2" "$K1")
read -r t22 e22 < <(count "$N2" "$K2")
grep -h "poses:" "$out/$solver-"*[0-9].out.log | sed 's/^/  /' >&2
awk -v s="$solver" -v t11="$t11" -v t12="$t12" -v t21="$t21" -v t22="$t22" \
  -v e11="$e11" -v e12="$e12" -v e21="$e21" -v e22="$e22" \
  -v n1="$N1" -v n2="$N2" -v k1="$K1" -v k2="$K2" 'BEGIN {
    d = (n2 - n1) * (k2 - k1)
    total = (t22 - t21 - t12 + t11) / d
    evaluation = (e22 - e21 - e12 + e11) / d
    printf "%s: %.0f instructions per pose per iteration: evaluation %.0f, everything else %.0f (%.2f x the evaluation)\n", s, total, evaluation, total - evaluation, (total - evaluation) / evaluation
  }'
