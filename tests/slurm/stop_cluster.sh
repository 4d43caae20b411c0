#!/usr/bin/env bash
# Stops what start_cluster.sh DIR started (by the pids it recorded): cancels the
# cluster's jobs, then slurmd, slurmctld and munged. Safe to run twice.
set -uo pipefail
dir=${1:?usage: stop_cluster.sh DIR}
[ -d "$dir" ] || exit 0
export PATH="$PATH:/usr/sbin:/sbin"
export SLURM_CONF="$dir/slurm.conf"
[ -f "$SLURM_CONF" ] && timeout 10 scancel --quiet --user=root >/dev/null 2>&1
stop() {  # pid file: TERM, then KILL after 10 s
  local file=$1 pid
  [ -f "$file" ] || return 0
  pid=$(cat "$file")
  rm -f "$file"
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null
  for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.1; done
  kill -KILL "$pid" 2>/dev/null
}
stop "$dir/slurmd.pid.own"
stop "$dir/slurmctld.pid.own"
stop "$dir/munge/munged.pid"
echo "stop_cluster: stopped the cluster in $dir"
