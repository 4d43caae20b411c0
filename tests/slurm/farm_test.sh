#!/usr/bin/env bash
# Farm tests against a real single-node Slurm (start_cluster.sh): run by CTest
# with the cluster as a fixture.   farm_test.sh SDFC CLUSTER_DIR CASE
#   still       8 shards through `sdfc farm submit`, merged == one `sdfc render`, byte for byte;
#               submitting the finished job again queues nothing
#   animation   6 frames x 2 shards, each frame == its own single render
#   fault       a shard's process killed mid-way: the in-job retry, and (no retries)
#               a resubmission that renders only the missing shard, give the same bytes
#   layers      2 shards of a --layers still: image.exr == one `sdfc render --layers`, byte for byte
#   broken      a scene with errors is refused before anything is submitted
#   video       ffmpeg fails in the merge job: status says the video was not made
set -euo pipefail
sdfc=${1:?sdfc binary}
cluster=${2:?cluster dir}
case_name=${3:?case}
here=$(cd "$(dirname "$0")" && pwd)
export SLURM_CONF="$cluster/slurm.conf"
export PATH="$PATH:/usr/sbin:/sbin"
work=$(mktemp -d "${TMPDIR:-/tmp}/sdfc_farm_${case_name}.XXXXXX")
trap 'rm -rf "$work"' EXIT
castle="$here/../../examples/castle.sdf"
morph="$here/../../examples/morph.sdf"
still_flags=(--size 64x36 --spp 248 --seed 7)

fail() { echo "FAIL: $*" >&2; exit 1; }

# Waits until no job of the farm directory is pending or running (180 s at most).
wait_for_job() {
  local dir=$1 ids
  ids=$(sed -n 's/^job //p' "$dir/farm.job" | paste -sd, -)
  for _ in $(seq 360); do
    [ -z "$(squeue --noheader --jobs="$ids" --states=PENDING,RUNNING,CONFIGURING,COMPLETING,REQUEUED 2>/dev/null)" ] && return 0
    sleep 0.5
  done
  squeue --states=all >&2 || true
  fail "jobs $ids of $dir still queued after 180 s"
}

case "$case_name" in
still)
  "$sdfc" render "$castle" "${still_flags[@]}" --denoise none -o "$work/single.exr" -q
  "$sdfc" farm submit "$castle" "${still_flags[@]}" --shards 8 -o "$work/job"
  wait_for_job "$work/job"
  "$sdfc" farm status "$work/job"
  [ "$(ls "$work/job/shards" | grep -c '^shard_.*\.exr$')" = 8 ] || fail "expected 8 shard files"
  cmp "$work/single.exr" "$work/job/image.exr" || fail "merged still differs from the single render"
  # Submitting the finished job again says so and queues nothing (it once queued another merge).
  record_before=$(cat "$work/job/farm.job")
  jobs_before=$(squeue --noheader --states=all --format=%i | wc -l)
  "$sdfc" farm submit "$castle" "${still_flags[@]}" --shards 8 -o "$work/job" 2> "$work/again.txt"
  cat "$work/again.txt"
  grep -q "is finished" "$work/again.txt" || fail "a finished job's resubmission does not say it is finished"
  [ "$(cat "$work/job/farm.job")" = "$record_before" ] || fail "a finished job's resubmission changed its record"
  [ "$(squeue --noheader --states=all --format=%i | wc -l)" = "$jobs_before" ] || fail "a finished job was submitted again"
  echo "still: 8 shards merged bit-identical to the single render; resubmitting the finished job queues nothing"
  ;;
layers)
  # 3 passes of 31 over 2 shards (31 and 62 samples): the layered EXR, exactly.
  layer_flags=(--size 48x27 --spp 93 --seed 7 --layers)
  "$sdfc" render "$castle" "${layer_flags[@]}" -o "$work/single.exr" -q
  "$sdfc" farm submit "$castle" "${layer_flags[@]}" --shards 2 -o "$work/job"
  wait_for_job "$work/job"
  "$sdfc" farm status "$work/job"
  cmp "$work/single.exr" "$work/job/image.exr" || fail "merged layers differ from the single render --layers"
  echo "layers: 2 shards of a --layers still merged bit-identical to the single render"
  ;;
animation)
  # fps 4: frame times 0, 0.25, ... are exact; --frames means the same frames for render and farm.
  "$sdfc" render "$morph" --size 64x36 --spp 64 --frames 0-5 --fps 4 --denoise none -o "$work/single.exr" -q
  video=()
  command -v ffmpeg >/dev/null && video=(--video "$work/job/anim.mp4")
  "$sdfc" farm submit "$morph" --size 64x36 --spp 64 --frames 0-5 --fps 4 --shards 2 -o "$work/job" "${video[@]}"
  wait_for_job "$work/job"
  "$sdfc" farm status "$work/job"
  for f in 0000 0001 0002 0003 0004 0005; do
    cmp "$work/single_$f.exr" "$work/job/frames/frame_$f.exr" || fail "frame $f differs from its single render"
  done
  [ ${#video[@]} -eq 0 ] || [ -s "$work/job/anim.mp4" ] || fail "no video"
  echo "animation: 6 frames x 2 shards, each bit-identical to its single render"
  ;;
fault)
  "$sdfc" render "$castle" "${still_flags[@]}" --denoise none -o "$work/single.exr" -q
  # 1. The killed shard is retried inside its job.
  SDFC_FAULT_KILL_SHARD=3 SDFC_FAULT_MARKER="$work/marker1" \
    "$sdfc" farm submit "$castle" "${still_flags[@]}" --shards 4 --retries 1 -o "$work/retry"
  wait_for_job "$work/retry"
  [ -f "$work/marker1" ] || fail "the fault was not injected"
  grep -q "retry 1 of 1" "$work/retry/logs/shard_3.log" || fail "shard 3 was not retried"
  cmp "$work/single.exr" "$work/retry/image.exr" || fail "retried job differs from the single render"
  # 2. No retries: the shard fails, the merge is cancelled; submitting again renders only it.
  SDFC_FAULT_KILL_SHARD=2 SDFC_FAULT_MARKER="$work/marker2" \
    "$sdfc" farm submit "$castle" "${still_flags[@]}" --shards 4 --retries 0 -o "$work/resume"
  wait_for_job "$work/resume"
  [ -f "$work/marker2" ] || fail "the fault was not injected"
  [ ! -e "$work/resume/shards/shard_00002.exr" ] || fail "the killed shard left a file"
  [ ! -e "$work/resume/image.exr" ] || fail "merged despite a failed shard"
  "$sdfc" farm status "$work/resume" | tee "$work/status.txt"
  grep -q "shards done: 3/4 (missing 2)" "$work/status.txt" || fail "status does not show shard 2 missing"
  before=$(stat -c %Y "$work/resume/shards/shard_00000.exr")
  "$sdfc" farm submit "$castle" "${still_flags[@]}" --shards 4 --retries 0 -o "$work/resume" | tee "$work/submit.txt"
  grep -q "(array 2)" "$work/submit.txt" || fail "resubmission did not submit shard 2 alone"
  wait_for_job "$work/resume"
  [ "$(stat -c %Y "$work/resume/shards/shard_00000.exr")" = "$before" ] || fail "a complete shard was rendered again"
  cmp "$work/single.exr" "$work/resume/image.exr" || fail "resumed job differs from the single render"
  echo "fault: retry and resume both bit-identical to the single render"
  ;;
video)
  # An ffmpeg that fails: the frames merge, the video is not made, and status
  # says so with the merge log (it said "(not yet)" forever).
  mkdir "$work/bin"
  printf '#!/bin/sh\necho "ffmpeg: stand-in that fails" >&2\nexit 1\n' > "$work/bin/ffmpeg"
  chmod +x "$work/bin/ffmpeg"
  PATH="$work/bin:$PATH" "$sdfc" farm submit "$morph" --size 32x18 --spp 64 --frames 0-1 --shards 1 \
    --video "$work/job/anim.mp4" -o "$work/job"
  wait_for_job "$work/job"
  "$sdfc" farm status "$work/job" | tee "$work/status.txt"
  [ -s "$work/job/frames/frame_0001.exr" ] || fail "the frames were not merged"
  grep -q "^video: .*anim.mp4 (not made: merge job [0-9]* ended without it; see .*/logs/merge_[0-9]*.log)" \
    "$work/status.txt" || fail "status does not say the video was not made"
  echo "video: a failed ffmpeg is reported by status with the merge log"
  ;;
broken)
  printf 'scene {\n  sphere(radus: 1)\n}\n' > "$work/broken.sdf"
  jobs_before=$(squeue --noheader --states=all --format=%i | wc -l)
  set +e
  "$sdfc" farm submit "$work/broken.sdf" --spp 8 --shards 2 -o "$work/job" 2> "$work/err.txt"
  status=$?
  set -e
  cat "$work/err.txt"
  [ "$status" = 1 ] || fail "expected exit 1 for a scene with errors, got $status"
  grep -q "broken.sdf:2:10: error" "$work/err.txt" || fail "no file:line:col diagnostic"
  [ ! -e "$work/job" ] || fail "the job directory was created"
  [ "$(squeue --noheader --states=all --format=%i | wc -l)" = "$jobs_before" ] || fail "a job was submitted"
  echo "broken: refused before any job existed"
  ;;
*) fail "unknown case $case_name" ;;
esac
