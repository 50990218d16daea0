# Shared by the scripts that time lumen renders side by side (sourced).

# The render time (s) lumen printed in output file $1, or the output and exit 1.
seconds() {
    t=$(sed -n 's/^time \([0-9.]*\) s.*/\1/p' "$1")
    if [ -z "$t" ]; then
        cat "$1" >&2
        exit 1
    fi
    echo "$t"
}

# $1 / $2 to three decimals: a speed ratio from two times.
ratio() {
    awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a / b }'
}

# Prints "$1 median M (range A to B, N rounds)" of the ratios in $2
# (separated by spaces).
report() {
    echo "$2" | tr ' ' '\n' | grep . | sort -n | awk -v label="$1" '
        { v[NR] = $1 }
        END {
            m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
            printf "%s median %.3f (range %.3f to %.3f, %d rounds)\n", label, m, v[1], v[NR], NR
        }'
}
