#!/bin/sh
# `make case=X RANKS=R` runs the solver through this: run-ranks.sh mpiexec [ARGS...] pdsolve CASE.json ...
#
# Why not mpiexec alone: Open MPI's mpirun (4.1, Debian 12) does not pass a Ctrl-C or SIGTERM on to
# the ranks; it stops the job itself, SIGCONT, then odls_base_sigkill_timeout seconds (1 s) later
# SIGTERM, then as long again SIGKILL. A rank inside a long step (a quasi-static load step can take
# a minute) is killed before it writes its checkpoint, and all the run's work is lost; a longer
# timeout only delays the SIGTERM as much. A second signal to mpirun (make passes one on) makes it
# exit at once and leave the ranks running.
#
# So mpiexec runs in a session of its own (the terminal's Ctrl-C and a signal to make's process
# group do not reach it), and a SIGINT, SIGTERM, SIGQUIT or SIGHUP that reaches this script is sent
# to the ranks, mpiexec's children on this machine: they finish the step under way, write
# checkpoint.bin and stop (pipeline/formats.md §5), and mpiexec ends with them. One rank is enough:
# the ranks agree after every step on whether any was signalled. Exit status: mpiexec's. A SIGKILL
# cannot be passed on: the line printed at the start says how to kill the session.
set -u
launcher=
pending=
signalled=
# The signal, to the ranks; before mpiexec exists, kept for when it does. Ranks still being started
# are waited for (pkill -P finds none yet) while mpiexec runs, for up to 10 s: once the ranks have
# ended mpiexec may linger, and then end as a zombie (not reaped while this runs), state Z.
running() {
  kill -0 "$launcher" 2>/dev/null && [ "$(cut -d ' ' -f 3 "/proc/$launcher/stat" 2>/dev/null)" != Z ]
}
forward() {
  signalled=1
  if [ -z "$launcher" ]; then
    pending=$1
    return
  fi
  tries=0
  while [ $tries -lt 100 ] && running; do
    pkill -"$1" -P "$launcher" && return
    tries=$((tries + 1))
    sleep 0.1
  done
}
trap 'forward INT' INT
trap 'forward TERM' TERM
trap 'forward TERM' QUIT
trap 'forward TERM' HUP  # the terminal closed: mpiexec, in its own session, would not hear of it
case $pending in INT) exit 130 ;; TERM) exit 143 ;; esac  # stopped before mpiexec started
# A background job of a shell without job control starts with SIGINT and SIGQUIT ignored, and the
# solver keeps an ignored SIGINT (run/signals.cpp): env gives them back their default action. Its
# stdin is /dev/null (POSIX), so it takes no keystrokes from the terminal.
setsid env --default-signal=INT,QUIT "$@" &
launcher=$!
echo "run-ranks.sh: mpiexec is process $launcher, in a session of its own: Ctrl-C or SIGTERM here stops the ranks" \
  "after their step (with a checkpoint); to kill them at once: pkill -KILL -s $launcher" >&2
[ -z "$pending" ] || forward "$pending"
# wait returns early when a trapped signal arrives: wait again until mpiexec has ended.
while :; do
  signalled=
  wait "$launcher"
  status=$?
  [ -n "$signalled" ] || exit "$status"
done
