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
# (pipeline/formats.md §5), and mpiexec ends with them. Exit status: mpiexec's.
set -u
setsid "$@" &
launcher=$!
# pkill -P: the processes whose parent is mpiexec, the ranks it started on this machine.
trap 'pkill -INT -P "$launcher"' INT
trap 'pkill -TERM -P "$launcher"' TERM
# wait returns early when a trapped signal arrives: wait again until mpiexec has ended.
while :; do
  wait "$launcher"
  status=$?
  kill -0 "$launcher" 2>/dev/null || exit "$status"
done
