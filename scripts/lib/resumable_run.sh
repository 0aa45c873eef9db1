# One simulation of a study, resumable; sourced, not run.
#
# resumable_run OUT NAME CYCLES ARGS...: the run OUT/NAME.h5 of `granmem simulate ARGS
# --cycles CYCLES` on one thread ($granmem), its checkpoint OUT/NAME.checkpoint.h5, its
# output appended to OUT/NAME.log. A run with a .done marker is skipped, one with a
# checkpoint is resumed (to CYCLES), any other started afresh; the marker is written when
# it finishes. Exported, so that `xargs -P` can run several at once.
resumable_run() {
  local out=$1 name=$2 cycles=$3
  shift 3
  local h5="$out/$name.h5" ckpt="$out/$name.checkpoint.h5" log="$out/$name.log"
  [[ -e $out/$name.done ]] && return 0
  local args
  if [[ -s $ckpt ]]; then
    args=(--resume "$ckpt" --cycles "$cycles")
  else
    rm -f "$h5"
    args=("$@" --cycles "$cycles" --out "$h5" --checkpoint "$ckpt")
  fi
  if OMP_NUM_THREADS=1 "$granmem" simulate --threads 1 "${args[@]}" >> "$log" 2>&1; then
    touch "$out/$name.done"
    echo "done: $name"
  else
    echo "failed or stopped: $name (see $log)" >&2
    return 1
  fi
}
export -f resumable_run
