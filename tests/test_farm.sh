#!/bin/sh
# test_farm.sh PARTRAY SOURCE_DIR - `partray farm` on real engines.
#
# 4 frames x 2 tiles of a particle-GI scene at 64x48 (tests/scenes/farm_gi.pov,
# the camera and a sphere move with the clock):
#  0. A scene that does not parse stops the farm before it plans (exit 1).
#  1. Slurm: a two-node cluster on loopback started by scripts/slurm_local.sh,
#     one task sent SIGTERM on its first run (--inject-fault: exit 143), the
#     merge job resubmits it; every merged frame is byte-identical (PFM) to
#     the frame rendered whole in one process (RMSE 0); every daemon the
#     script started is gone afterwards (checked by PID).
#  2. GNU parallel on this machine (sshloginfile ":"), another task made to
#     fail the same way, recovered by --retries; frames identical again
#     (the tiles of a frame share a GI cache the farm names in its
#     directory, one per frame as the sphere moves).
#  3. The parallel farm run again on the same directory renders nothing.
#  4. GNU parallel over ssh: an sshd started here on 127.0.0.1 at a free high
#     port (a fixture: its own host key, a user key made here, no PAM, no
#     password), two ssh logins to it (127.0.0.1 and localhost) in the
#     sshloginfile, a task made to fail on its first run; both logins run
#     tasks, the frames are identical again, and the sshd is stopped by PID.
set -u
BIN=$1
SRC=$2
fail() { echo "FAIL: $*"; exit 1; }
T=$(mktemp -d /tmp/partray-farm-XXXXXX)
SL="$T/slurm"
pids=""
cleanup() {
    "$SRC/scripts/slurm_local.sh" stop "$SL" >/dev/null 2>&1 || true
    [ -f "$T/ssh/sshd.pid" ] && kill "$(cat "$T/ssh/sshd.pid")" 2>/dev/null
    true
}
trap cleanup EXIT INT TERM
for b in parallel sbatch slurmctld slurmd munged sshd ssh ssh-keygen; do
    command -v "$b" >/dev/null 2>&1 || [ -x "/usr/sbin/$b" ] || fail "$b missing (scripts/setup.sh installs it)"
done
cp "$SRC/tests/scenes/farm_gi.pov" "$T/" || fail "copy scene"
cd "$T" || fail "cd"
OPTS="--size 64x48 --particles 10000 +KFI1 +KFF4"

# a scene error stops the farm before it plans anything (exit 1, no DIR)
printf 'camera { location -5 look_at 0 }\nsphere { 0, 1 oops }\n' >bad.pov
"$BIN" farm bad.pov --size 32x24 --dir wbad -o bad.pfm 2>bad.log
rc=$?
[ $rc -eq 1 ] || fail "farm on a scene that does not parse: exit $rc, wanted 1"
grep -q "bad.pov:2:.*error" bad.log || fail "farm on a bad scene: no located error: $(cat bad.log)"
[ -e wbad ] && fail "farm on a bad scene made its directory"
echo "ok: a scene error stops the farm before planning"

# the frames rendered whole, one process each
for f in 1 2 3 4; do
    "$BIN" render farm_gi.pov $OPTS --frame $f -q -o "ref.pfm" || fail "reference frame $f"
done
[ -f ref1.pfm ] && [ -f ref4.pfm ] || fail "reference frames missing"
cmp -s ref1.pfm ref2.pfm && fail "frames 1 and 2 are the same: the scene does not move"

same_frames() { # DIR-PREFIX
    for f in 1 2 3 4; do
        cmp "ref$f.pfm" "$1$f.pfm" || fail "$1$f.pfm differs from the one-process render of frame $f"
    done
    echo "ok: 4 merged frames byte-identical to the one-process renders ($1*.pfm)"
}

# ---- 1. Slurm ---------------------------------------------------------
t0=$(date +%s)
"$SRC/scripts/slurm_local.sh" start "$SL" 2 || fail "slurm cluster did not start (logs in $SL)"
pids=$(cat "$SL"/*.pid)
[ "$(echo "$pids" | wc -w)" -eq 4 ] || fail "expected 4 daemons (munged, slurmctld, 2 slurmd), pids: $pids"
. "$SL/env"
sinfo
"$BIN" farm farm_gi.pov $OPTS --tiles 2 --dir ws -o slurm.pfm --engine slurm --inject-fault 2:1 --timeout 300
rc=$?
[ $rc -eq 0 ] || { cat ws/logs/* 2>/dev/null | tail -40; fail "farm --engine slurm exit $rc"; }
hist=$(tr '\n' ' ' <ws/status/3.history)
echo "task 3 (frame 2, tile 1) exits: $hist"
[ "$hist" = "143 0 " ] || fail "the faulted Slurm task should have exited 143, then 0 (got: $hist)"
[ "$(cat ws/round)" = 2 ] || fail "expected one resubmission round"
same_frames slurm
"$SRC/scripts/slurm_local.sh" stop "$SL" || fail "slurm stop"
for p in $pids; do
    kill -0 "$p" 2>/dev/null && fail "daemon $p still running after stop"
done
echo "ok: slurm run in $(( $(date +%s) - t0 )) s, daemons $(echo $pids) stopped"

# ---- 2. GNU parallel ------------------------------------------------------
t0=$(date +%s)
echo ":" >hosts
"$BIN" farm farm_gi.pov $OPTS --tiles 2 --dir wp -o par.pfm --engine parallel --sshloginfile hosts --jobs 2 \
    --retries 2 --inject-fault 3:0 || fail "farm --engine parallel"
ls wp/gi1.gic wp/gi4.gic >/dev/null || fail "no per-frame GI caches in wp/ (the farm's --gi-cache)"
hist=$(tr '\n' ' ' <wp/status/4.history)
echo "task 4 (frame 3, tile 0) exits: $hist"
[ "$hist" = "143 0 " ] || fail "the faulted parallel task should have exited 143, then 0 (got: $hist)"
same_frames par
echo "ok: parallel run in $(( $(date +%s) - t0 )) s"

# ---- 3. resume: nothing left to do ---------------------------------------
lines=$(wc -l <wp/joblog)
"$BIN" farm farm_gi.pov $OPTS --tiles 2 --dir wp -o par.pfm --engine parallel --sshloginfile hosts 2>farm3.log ||
    fail "second parallel farm"
cat farm3.log
grep -q "frames 4/4 merged" farm3.log || fail "second run did not find the 4 frames"
for i in 0 1 2 3 4 5 6 7; do
    [ "$(wc -l <wp/status/$i.history)" -le 2 ] || fail "task $i ran again on the second run"
done
same_frames par
echo "ok: the second run on the same directory rendered nothing (joblog $lines lines before)"

# ---- 4. GNU parallel over ssh ---------------------------------------------
t0=$(date +%s)
K="$T/ssh"
mkdir -p "$K" /run/sshd 2>/dev/null
ssh-keygen -q -t ed25519 -N '' -f "$K/host_key" || fail "ssh-keygen host key"
ssh-keygen -q -t ed25519 -N '' -f "$K/user_key" || fail "ssh-keygen user key"
cp "$K/user_key.pub" "$K/authorized_keys"
SSHD=$(command -v sshd || echo /usr/sbin/sshd)
port=""
for try in 1 2 3 4 5; do
    p=$(( 20000 + ($$ * 7 + try * 131) % 20000 ))
    cat >"$K/sshd_config" <<EOF
Port $p
ListenAddress 127.0.0.1
HostKey $K/host_key
PidFile $K/sshd.pid
AuthorizedKeysFile $K/authorized_keys
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
PermitRootLogin prohibit-password
EOF
    "$SSHD" -f "$K/sshd_config" -E "$K/sshd.log" || continue
    for i in 1 2 3 4 5 6 7 8 9 10; do [ -s "$K/sshd.pid" ] && break; sleep 0.2; done
    [ -s "$K/sshd.pid" ] && { port=$p; break; }
done
[ -n "$port" ] || { cat "$K/sshd.log"; fail "sshd did not start"; }
sshd_pid=$(cat "$K/sshd.pid")
S="ssh -p $port -i $K/user_key -o StrictHostKeyChecking=no -o UserKnownHostsFile=$K/known_hosts -o BatchMode=yes -o LogLevel=ERROR"
$S 127.0.0.1 true || { cat "$K/sshd.log"; fail "ssh to 127.0.0.1:$port"; }
printf '1/%s 127.0.0.1\n1/%s localhost\n' "$S" "$S" >sshhosts
"$BIN" farm farm_gi.pov $OPTS --tiles 2 --dir wssh -o ssh.pfm --engine parallel --sshloginfile sshhosts --jobs 1 \
    --retries 2 --inject-fault 4:1 || fail "farm --engine parallel over ssh"
hist=$(tr '\n' ' ' <wssh/status/7.history)
echo "task 7 (frame 4, tile 1) exits over ssh: $hist"
[ "$hist" = "143 0 " ] || fail "the faulted ssh task should have exited 143, then 0 (got: $hist)"
for h in 127.0.0.1 localhost; do
    n=$(awk -F'\t' -v h="$h" 'NR > 1 && $2 ~ (" " h "$") { c++ } END { print c + 0 }' wssh/joblog)
    echo "tasks run through the ssh login to $h: $n"
    [ "$n" -ge 1 ] || fail "no task ran through the ssh login to $h"
done
same_frames ssh
kill "$sshd_pid"
for i in 1 2 3 4 5 6 7 8 9 10; do kill -0 "$sshd_pid" 2>/dev/null || break; sleep 0.2; done
kill -0 "$sshd_pid" 2>/dev/null && fail "sshd $sshd_pid still running after kill"
rm -f "$K/sshd.pid"
echo "ok: parallel over ssh (port $port) in $(( $(date +%s) - t0 )) s, sshd $sshd_pid stopped"
cd /
rm -rf "$T"
echo PASS
