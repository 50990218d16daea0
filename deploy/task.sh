#!/bin/sh
# Renders one share of a render split across a cluster: the task script that
# a Slurm job array and a Kubernetes Indexed Job both run (docs/distributed.md).
#
# The share K of N comes from the engine's own variables, so the same script
# serves both:
#   K: LUMEN_TASK_INDEX, else SLURM_ARRAY_TASK_ID, else JOB_COMPLETION_INDEX
#   N: LUMEN_TASK_COUNT, else SLURM_ARRAY_TASK_COUNT, else LUMEN_PARTS
# LUMEN_TASK_COUNT comes first because SLURM_ARRAY_TASK_COUNT is the size of
# the array as submitted: an array resubmitted for one failed index has one
# task, not N.
#
# Other settings:
#   LUMEN_SCENE      the scene (built-in name or file), the same for every task
#   LUMEN_PARTS_DIR  the directory, shared by every task, for the part files
#   LUMEN_ARGS       further `lumen render` options (--spp, --seed, ...), the
#                    same for every task; split at spaces, never globbed
#   LUMEN_BIN        the lumen command [lumen]
#
# It runs
#   lumen render SCENE --part K/N -o DIR/part-K.lumen-part [--resume] LUMEN_ARGS
# The part file is its own checkpoint: lumen rewrites it after every pass,
# on the shared volume, so a task that is killed and requeued, on this node
# or another, continues where it stopped. --resume is given whenever the part
# file exists: lumen then continues it, or returns at once when the part is
# already complete. A task that never started is rendered afresh.
#
# Exit status: lumen's (0: the part is complete; 1: it is not, for instance
# --time-limit ran out, the part file saved for --resume; 130: stopped by a
# signal, the part file saved); 2 when the settings are missing or wrong.
set -eu

me=lumen-task

refuse() {
    echo "$me: error: $*" >&2
    exit 2
}

# The first of the named variables that is set and not empty, as "NAME=VALUE";
# nothing when none is.
first_set() {
    for name in "$@"; do
        eval "value=\${$name:-}"
        if [ -n "$value" ]; then
            printf '%s=%s\n' "$name" "$value"
            return 0
        fi
    done
}

# A decimal count without sign or leading zero, at most 9 digits so that the
# shell's arithmetic cannot overflow. Leading zeros are refused rather than
# read: the shell would take 010 for 8.
check_integer() {
    case $2 in
        0 | [1-9] | [1-9][0-9] | [1-9][0-9][0-9] | [1-9][0-9][0-9][0-9] | \
            [1-9][0-9][0-9][0-9][0-9] | [1-9][0-9][0-9][0-9][0-9][0-9] | \
            [1-9][0-9][0-9][0-9][0-9][0-9][0-9] | \
            [1-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9] | \
            [1-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9][0-9]) ;;
        *) refuse "$1 is '$2', not a whole number (0, 1, 2, ...)" ;;
    esac
}

index_var=$(first_set LUMEN_TASK_INDEX SLURM_ARRAY_TASK_ID JOB_COMPLETION_INDEX)
[ -n "$index_var" ] ||
    refuse "no task index: set LUMEN_TASK_INDEX, or run as a Slurm array task (SLURM_ARRAY_TASK_ID) or a Kubernetes Indexed Job (JOB_COMPLETION_INDEX)"
count_var=$(first_set LUMEN_TASK_COUNT SLURM_ARRAY_TASK_COUNT LUMEN_PARTS)
[ -n "$count_var" ] ||
    refuse "no task count: set LUMEN_TASK_COUNT (or LUMEN_PARTS) to the number of parts"

check_integer "${index_var%%=*}" "${index_var#*=}"
check_integer "${count_var%%=*}" "${count_var#*=}"
index=${index_var#*=}
count=${count_var#*=}
[ "$count" -gt 0 ] || refuse "${count_var%%=*} is 0: a render needs at least one part"
[ "$index" -lt "$count" ] ||
    refuse "task index $index (${index_var%%=*}) is not below the task count $count (${count_var%%=*}); indexes run from 0 to $((count - 1))"

scene=${LUMEN_SCENE:-}
dir=${LUMEN_PARTS_DIR:-}
[ -n "$scene" ] || refuse "LUMEN_SCENE is not set: the scene to render (built-in name or file)"
[ -n "$dir" ] || refuse "LUMEN_PARTS_DIR is not set: the shared directory for the part files"
[ -d "$dir" ] || refuse "LUMEN_PARTS_DIR $dir is not a directory (it must exist and be shared by every task)"

# These options are the script's to give; a second copy in LUMEN_ARGS would
# either be refused by lumen or point the task at another file. --checkpoint
# has no place at all: the part file is the checkpoint.
set -f
for arg in ${LUMEN_ARGS:-}; do
    case $arg in
        -o | --output | --output=* | -o?* | --part | --part=* | --resume)
            refuse "LUMEN_ARGS holds $arg, which $me sets itself (output, part, resume)"
            ;;
        --checkpoint | --checkpoint=*)
            refuse "LUMEN_ARGS holds $arg: a part file is its own checkpoint, so lumen takes no --checkpoint with --part"
            ;;
    esac
done

part="$dir/part-$index.lumen-part"
resume=
if [ -e "$part" ]; then
    resume=--resume
fi

echo "$me: part $index/$count of $scene -> $part${resume:+ (resuming)} on $(hostname 2>/dev/null || echo '?')" >&2
# exec: lumen receives the engine's SIGTERM itself (Slurm requeue or
# preemption, a Kubernetes pod deletion), saves its part file and exits 130.
# shellcheck disable=SC2086 # LUMEN_ARGS is split on purpose; globbing is off.
exec "${LUMEN_BIN:-lumen}" render "$scene" --part "$index/$count" \
    -o "$part" $resume ${LUMEN_ARGS:-}
