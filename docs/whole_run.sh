#!/bin/bash
# s/TU of whole runs as users run them, as the difference of two run lengths (issue 14):
# bash docs/whole_run.sh SCENE T1 T2 THREADS [--set key=value ...]   (from the repository root, after cargo build --release)
B=${B:-target/release/monolayer}
scene=$1; t1=$2; t2=$3; th=$4; shift 4
extra=("$@")
run() { local t=$1; local s=$(date +%s.%N); $B run $scene --out "${OUT:-/tmp/monolayer-whole}" --overwrite -q --threads $th --set 'model.pressure="interaction"' --set run.relax_time=0 --set run.time=$t --set run.output_every=$t --set run.series_every=$t --set run.checkpoint_every=$t "${extra[@]}"; local e=$(date +%s.%N); echo "$e - $s" | bc; }
a=$(run $t1); b=$(run $t2); echo "scale=5; ($b - $a)/($t2 - $t1)" | bc
