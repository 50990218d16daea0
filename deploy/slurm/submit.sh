#!/bin/sh
# Submits a render split across a Slurm cluster: a job array of N tasks, each
# rendering one part, and a merge job that runs once every task has ended.
#
#   deploy/slurm/submit.sh SCENE PARTS_DIR N OUT [lumen render options...]
#
# PARTS_DIR must be on a file system every node sees (it is created); the
# logs go to PARTS_DIR/logs. Extra sbatch options for both jobs (partition,
# account, time limit, --cpus-per-task, ...) go in LUMEN_SBATCH_ARGS.
# Prints the two job ids as shell assignments, `render=ID` and `merge=ID`.
#
# LUMEN_ARRAY=K[,K...] submits only those indexes (any `sbatch --array` list)
# and a new merge after them: the way to rerun failed tasks with the same
# command. Tasks whose part is complete return at once, so rerunning every
# index is harmless too.
#
# The merge depends on the array with afterany, not afterok: with afterok a
# task that fails leaves the merge pending forever (DependencyNeverSatisfied),
# even once the task is requeued and succeeds. The merge checks the parts
# itself and refuses an incomplete set (docs/distributed.md).
set -eu

usage() {
    echo "usage: $0 SCENE PARTS_DIR N OUT [lumen render options...]" >&2
    exit 2
}
[ $# -ge 4 ] || usage
scene=$1
dir=$2
count=$3
out=$4
shift 4
case $count in
    '' | *[!0-9]* | 0*) echo "submit: error: N is '$count', not a number of parts (1, 2, ...)" >&2; exit 2 ;;
esac
array=${LUMEN_ARRAY:-0-$((count - 1))}
case $array in
    '' | *[!0-9,%:-]*) echo "submit: error: LUMEN_ARRAY is '$array', not an sbatch --array list of indexes (3 or 1,5 or 0-7)" >&2; exit 2 ;;
esac
for arg in "$@"; do
    case $arg in
        *' '*) echo "submit: error: the lumen option '$arg' holds a space, which LUMEN_ARGS cannot carry" >&2; exit 2 ;;
    esac
done

here=$(cd "$(dirname "$0")" && pwd)
deploy=$(dirname "$here")
mkdir -p "$dir/logs"
dir=$(cd "$dir" && pwd)
case $out in
    /*) ;;
    *) out="$(pwd)/$out" ;;
esac

LUMEN_SCENE=$scene
LUMEN_PARTS_DIR=$dir
LUMEN_TASK_COUNT=$count
LUMEN_OUT=$out
LUMEN_ARGS="$*"
LUMEN_TASK_SCRIPT="$deploy/task.sh"
LUMEN_MERGE_SCRIPT="$deploy/merge.sh"
export LUMEN_SCENE LUMEN_PARTS_DIR LUMEN_TASK_COUNT LUMEN_OUT LUMEN_ARGS \
    LUMEN_TASK_SCRIPT LUMEN_MERGE_SCRIPT

set -f
# shellcheck disable=SC2086 # LUMEN_SBATCH_ARGS is split on purpose.
render=$(sbatch --parsable --array="$array" --export=ALL \
    --output="$dir/logs/render-%A_%a.out" ${LUMEN_SBATCH_ARGS:-} \
    "$here/render.sbatch")
render=${render%%;*} # --parsable prints "ID" or "ID;CLUSTER"
echo "render=$render"
# shellcheck disable=SC2086
merge=$(sbatch --parsable --dependency="afterany:$render" --kill-on-invalid-dep=no \
    --export=ALL --output="$dir/logs/merge-%j.out" ${LUMEN_SBATCH_ARGS:-} \
    "$here/merge.sbatch")
merge=${merge%%;*}

echo "merge=$merge"
echo "submit: render array $render (parts $array of $count into $dir), merge $merge into $out after it" >&2
