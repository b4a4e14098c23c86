#!/bin/sh
# test_mpi_example.sh -- examples/diffusion2d_mpi (each rank its own rows,
# SPMD) at np = 1, 2, 3 prints the same summary numbers as the embedded
# examples/diffusion2d: the heat total and the maximum, digit for digit
# as printed (10 significant digits).
#
#     sh tests/test_mpi_example.sh MPIRUN DIFFUSION2D DIFFUSION2D_MPI OUTDIR
set -u
MPIRUN=$1 SEQ=$2 PAR=$3 OUT=$4
mkdir -p "$OUT"
want=$("$SEQ" -n 40 -s 20 -o "$OUT/seq.pgm" | grep -E '^(steps|heat)' | sed 's/time=[^ ]* //')
[ -n "$want" ] || { echo "FAIL: diffusion2d printed no summary"; exit 1; }
fail=0
for np in 1 2 3; do
    got=$("$MPIRUN" -np $np "$PAR" -n 40 -s 20 -o "$OUT/mpi$np.pgm" | grep -E '^(steps|heat)' |
          sed 's/time=[^ ]* //')
    if [ "$got" != "$want" ]; then
        echo "FAIL: np=$np printed"; echo "$got"; echo "embedded printed"; echo "$want"
        fail=$((fail + 1))
    fi
done
echo "$((3 - fail)) passed, $fail failed"
[ $fail -eq 0 ]
