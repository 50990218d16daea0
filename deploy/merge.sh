#!/bin/sh
# Merges the parts of a render split across a cluster into one image: the
# merge step that Slurm (deploy/slurm/merge.sbatch) and Kubernetes
# (deploy/k8s/merge-job.yaml) both run (docs/distributed.md).
#
#   LUMEN_PARTS_DIR    the directory holding part-0.lumen-part ... part-(N-1)
#   LUMEN_TASK_COUNT   N, the number of parts (else LUMEN_PARTS)
#   LUMEN_OUT          the image to write (.png, .exr, .pfm, .ppm)
#   LUMEN_MERGE_ARGS   further `lumen merge` options; split at spaces
#   LUMEN_BIN          the lumen command [lumen]
#
# The parts are named one by one, 0 to N-1, rather than globbed, so that a
# part left over from an earlier render with more parts is not taken in and a
# missing one is named. lumen merge itself refuses parts that are incomplete,
# overlapping, corrupt or of another scene. When parts are missing this
# script says which indexes to rerun and exits 1 without merging, unless
# LUMEN_MERGE_ARGS holds --partial (a preview of the parts there so far).
set -eu

me=lumen-merge

refuse() {
    echo "$me: error: $*" >&2
    exit 2
}

dir=${LUMEN_PARTS_DIR:-}
count=${LUMEN_TASK_COUNT:-${LUMEN_PARTS:-}}
out=${LUMEN_OUT:-}
[ -n "$dir" ] || refuse "LUMEN_PARTS_DIR is not set: the directory holding the part files"
[ -n "$out" ] || refuse "LUMEN_OUT is not set: the image to write"
case $count in
    '' | *[!0-9]* | 0*) refuse "LUMEN_TASK_COUNT is '$count', not the number of parts (1, 2, ...)" ;;
esac

set -f
set --
missing=
i=0
while [ "$i" -lt "$count" ]; do
    part="$dir/part-$i.lumen-part"
    if [ -e "$part" ]; then
        set -- "$@" "$part"
    else
        missing="${missing:+$missing,}$i"
    fi
    i=$((i + 1))
done

partial=
for arg in ${LUMEN_MERGE_ARGS:-}; do
    [ "$arg" != --partial ] || partial=yes
done

if [ -n "$missing" ] && [ -n "$partial" ]; then
    echo "$me: note: no part file yet for index $missing of $count; previewing the others" >&2
    [ $# -gt 0 ] || refuse "no part file in $dir yet"
elif [ -n "$missing" ]; then
    echo "$me: error: no part file for index $missing of $count in $dir; rerun those tasks, then this merge (docs/distributed.md#when-a-task-fails)" >&2
    exit 1
fi

echo "$me: merging $# of $count parts from $dir into $out" >&2
# shellcheck disable=SC2086 # LUMEN_MERGE_ARGS is split on purpose; globbing is off.
exec "${LUMEN_BIN:-lumen}" merge "$@" -o "$out" ${LUMEN_MERGE_ARGS:-}
