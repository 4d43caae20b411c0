#!/usr/bin/env bash
# Starts a single-node Slurm cluster on this machine for the farm tests: munged,
# slurmctld and slurmd run directly (no systemd; works in a chroot with /proc,
# /dev and /sys mounted), as root, with every state, log, pid and socket file in
# DIR. Waits until the node is idle. Stop it with stop_cluster.sh DIR.
#   start_cluster.sh DIR        then: export SLURM_CONF=DIR/slurm.conf
# Needs Debian's slurmctld slurmd slurm-client munge (tools/setup.sh installs them).
set -euo pipefail
dir=${1:?usage: start_cluster.sh DIR}
here=$(cd "$(dirname "$0")" && pwd)
"$here/stop_cluster.sh" "$dir" >/dev/null 2>&1 || true
rm -rf "$dir"
mkdir -p "$dir"/munge "$dir"/ctld "$dir"/spool
dir=$(cd "$dir" && pwd)
for tool in munged slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || [ -x "/usr/sbin/$tool" ] || {
    echo "start_cluster: $tool not found (apt-get install slurmctld slurmd slurm-client munge)" >&2; exit 1; }
done
export PATH="$PATH:/usr/sbin:/sbin"

# Free TCP ports on the loopback interface, so clusters of parallel runs do not meet.
free_port() {
  local port
  for _ in $(seq 200); do
    port=$((20000 + RANDOM % 20000))
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || { echo "$port"; return; }
  done
  echo "start_cluster: no free port" >&2; exit 1
}
ctld_port=$(free_port)
slurmd_port=$(free_port)
while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(free_port); done
node=$(uname -n)
node=${node%%.*}

# munge: a private key and socket (munged refuses keys others may read).
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$dir/munge"
chmod 400 "$dir/munge/munge.key"
munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
  --seed-file="$dir/munge/munged.seed"

cat > "$dir/slurm.conf" <<CONF
# Single-node test cluster written by tests/slurm/start_cluster.sh
ClusterName=sdfctest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/ctld
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
PlugStackConfig=$dir/plugstack.conf
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
SwitchType=switch/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
MinJobAge=600
KillWait=5
InactiveLimit=0
SlurmdTimeout=60
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=debug Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
: > "$dir/plugstack.conf"
export SLURM_CONF="$dir/slurm.conf"

# Foreground daemons (-D) in the background of this script's process group; their
# pids are recorded for stop_cluster.sh.
setsid slurmctld -D -i -f "$SLURM_CONF" > "$dir/slurmctld.out" 2>&1 < /dev/null &
echo $! > "$dir/slurmctld.pid.own"
setsid slurmd -D -N "$node" -f "$SLURM_CONF" > "$dir/slurmd.out" 2>&1 < /dev/null &
echo $! > "$dir/slurmd.pid.own"

for _ in $(seq 120); do
  state=$(sinfo --noheader --nodes="$node" --format=%T 2>/dev/null || true)
  case "$state" in
    idle*) echo "start_cluster: node $node idle (SLURM_CONF=$SLURM_CONF)"; exit 0 ;;
    drain*|down*) scontrol update nodename="$node" state=resume >/dev/null 2>&1 || true ;;
  esac
  sleep 0.5
done
echo "start_cluster: the node did not become idle in 60 s; logs in $dir" >&2
tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" "$dir/slurmctld.out" "$dir/slurmd.out" >&2 2>/dev/null || true
exit 1
