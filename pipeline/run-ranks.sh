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
# So mpiexec runs in a session of its own (the terminal's Ctrl-C and a SIGTERM to make's process
# group do not reach it), and a SIGINT or SIGTERM that reaches this script is sent to the ranks,
# its children, as it came: each finishes the step under way, they write checkpoint.bin and stop
# (pipeline/formats.md §5), and mpiexec ends with them. Exit status: mpiexec's. (In a script without
# job control the background mpiexec reads /dev/null, so it takes no keystrokes from the terminal.)
set -u
launcher=
# pkill -P: the processes whose parent is mpiexec, the ranks it started on this machine. A signal
# before mpiexec has started stops the script there.
forward() {
  [ -n "$launcher" ] || exit "$2"
  pkill -"$1" -P "$launcher"
}
trap 'forward INT 130' INT
trap 'forward TERM 143' TERM
# The terminal closed: mpiexec, in its own session, would not hear of it; stop as for a SIGTERM.
trap 'forward TERM 129' HUP
setsid "$@" &
launcher=$!
# wait returns early when a trapped signal arrives: wait again until mpiexec has ended.
while :; do
  wait "$launcher"
  status=$?
  kill -0 "$launcher" 2>/dev/null || exit "$status"
done
