# Shared by scripts/gain_vs_exact.sh and scripts/review_cost.sh (sourced, not run):
# `ir CMD…` prints the instructions CMD executes (valgrind's callgrind), and `make_acc FILE`
# writes a 6,070-row 100 Hz series stamped in Unix seconds (an accelerometer-like log).
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$@" 2>&1 >/dev/null | sed -n 's/.*Collected : //p'; }
make_acc() {
python3 - "$1" <<'PY'
import math, random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("t,y\n")
    for i in range(6070):
        s = i * 0.01
        f.write(f"{1.7e9 + s:.2f},{9.81 + 2 * math.sin(3 * s) + 0.5 * math.sin(17 * s) + random.gauss(0, 0.05)}\n")
PY
}
