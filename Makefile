# Orchestration only: each stage is a program, files are the interface (pipeline/formats.md).
#   make case=membrane        mesh → node cloud → solve → figures and Gmsh views, in out/membrane/
#   make figures case=X       redraw figures and Gmsh views from existing results
#   make case=X config=Y      run cases/X/Y.yaml (a variant of case X) into out/X-Y/
#   make case=X RANKS=R       solve on R MPI ranks (mpiexec --oversubscribe -np R; OMP_NUM_THREADS threads each, cores/R if unset)
#   make FORCE=1 case=X       run even when preprocess's work plan is above its limits (> 1 h, or
#                             more than half the free memory or disk: pipeline/cost.py)
#   make test                 build everything and run every test (then test-asan)
#   make validate             full plate_with_hole, traction, branching (and config=lps), three_point_bending, drum runs, wave, wave_lps and static models + checks → out/validate/report.md
#                             then the tests marked slow that make test leaves out
#   make test-asan            the solver's tests under AddressSanitizer + UBSan (build/solver-asan)
#   make fuzz                 libFuzzer on the solver's readers, then the case-file loader's mutation
#                             fuzzer (pipeline/fuzz_case.py) and pdsolve's command line
#                             (pipeline/fuzz_cli.py), FUZZ_SECONDS (60) each (clang)
#   make bench                speed of the bond kernel on 3D bricks, and of LAMMPS PERI on one → out/bench/ (docs/performance.md)
#   make bench-accuracy       error against run time: Verlet, adaptive, quasi_static, mixed → out/bench/accuracy.csv (docs/accuracy.md)
#   make bench-implicit       implicit dynamics vs Verlet on a drum lattice and the membrane → out/bench/implicit.csv
#   make help                 this list
# Only stale stages rerun: an edit to the .yaml reruns preprocessing and what follows,
# a change of the gmsh parameters in the .yaml also re-meshes.

case    ?= membrane

# case= and config= become paths (cases/<case>/, out/<case>/), and make expands command-line
# variables in every recipe's environment: `case=a\`cmd\`` or `case=$$(shell cmd)` would run cmd,
# and `case=../x` would read and delete outside the repository. So each is checked here, once,
# before anything expands it: one word of SAFE_NAME_CHARS only, naming what exists.
# $(value) and := never expand the text they hold, so a `$(shell …)` in the value stays text.
SAFE_NAME_CHARS := a b c d e f g h i j k l m n o p q r s t u v w x y z \
                   A B C D E F G H I J K L M N O P Q R S T U V W X Y Z 0 1 2 3 4 5 6 7 8 9 _ -
# $(call unsafe_chars,VAR,CHARS): empty if the unexpanded value of VAR is made of CHARS (and spaces)
# alone. None of the shell's special characters is in any list given to it, so a checked value
# that reaches a recipe is words and nothing else.
unsafe_chars = $(strip $(eval _pd_rest := $$(value $(1)))$(foreach c,$(2),$(eval \
    _pd_rest := $$(subst $$(c),,$$(_pd_rest))))$(_pd_rest))
# $(call unsafe_name,VAR): empty if the unexpanded value of VAR matches [A-Za-z0-9_-]+ (one word).
unsafe_name = $(strip $(call unsafe_chars,$(1),$(SAFE_NAME_CHARS))$(if $(filter-out 1,$(words $(value $(1)))),bad))
DIGITS := 0 1 2 3 4 5 6 7 8 9
# $(call not_count,VAR): empty if VAR is one word of digits (a whole number ≥ 0).
not_count = $(strip $(call unsafe_chars,$(1),$(DIGITS))$(if $(filter-out 1,$(words $(value $(1)))),bad))

# Issue 36, item 4: every variable of this file that reaches a shell is either computed here and
# refused from the command line (`make clean-case OUT=/tmp/x` ran `rm -rf -- '/tmp/x'`), or a
# setting checked like case= below (`LOCK_WAIT="0' …; touch /tmp/pwn; echo '"` ran the touch).
# `override` keeps them ours under `make -e` too. SOLVER_SOURCES (tests set it empty) reaches no shell.
INTERNAL_VARIABLES := ALL_SOLVER_TARGETS ASAN_EXCLUDE ASAN_EXCLUDE_SPACE PD_LOCK_FD OUT CASEDIR YAML MESH GIVEN_MESH CHECKPOINT MPIRUN RANK_THREADS PY PYTEST DEPS \
    ASAN_DIR FUZZ_DIR FUZZ_TARGETS BENCH_DEPS PD_CASE_LOCK LOCKED_GOALS DRY_RUN MAKE SHELL .SHELLFLAGS
$(foreach v,$(INTERNAL_VARIABLES),$(if $(filter command line,$(origin $(v))),$(error $(v) is set by \
    this Makefile, not on the command line: $(if $(filter OUT CASEDIR YAML MESH CHECKPOINT,$(v)),the output \
    folder follows from case= and config= (out/<case>[-<config>]/),give case=, config=, RANKS=, SOLVER=, LOCK_WAIT= and \
    the other settings of `make help` instead))))
# Settings of numbers: digits only (LOCK_WAIT may have a decimal point, as flock -w takes).
ifneq ($(call unsafe_chars,LOCK_WAIT,$(DIGITS) .)$(filter-out 0 1,$(words $(value LOCK_WAIT))),)
  $(error LOCK_WAIT='$(value LOCK_WAIT)' is not a number of seconds: digits and '.' only, e.g. LOCK_WAIT=600)
endif
# Its characters known safe, its form: a number as flock -w reads it (`..` passed, then flock failed).
ifneq ($(if $(value LOCK_WAIT),$(shell printf '%s\n' '$(value LOCK_WAIT)' | grep -Eqx '[0-9]+(\.[0-9]*)?|\.[0-9]+' || echo bad)),)
  $(error LOCK_WAIT='$(value LOCK_WAIT)' is not a number of seconds, e.g. LOCK_WAIT=600 or LOCK_WAIT=2.5)
endif
$(foreach v,JOBS FUZZ_SECONDS,$(if $(and $(value $(v)),$(call not_count,$(v))),$(error \
    $(v)='$(value $(v))' is not a whole number: digits only, e.g. $(v)=2)))
$(foreach v,BENCH_SIDES BENCH_MPI_SIDES,$(if $(call unsafe_chars,$(v),$(DIGITS)),$(error \
    $(v)='$(value $(v))' is not a list of brick sides: numbers separated by spaces, e.g. $(v)="40 100")))
# Free-form options of the benchmarks and the path of another solver: words of these characters only.
SAFE_ARG_CHARS := $(SAFE_NAME_CHARS) . , = : / +
$(foreach v,ACCURACY_ARGS IMPLICIT_ARGS SOLVER,$(if $(call unsafe_chars,$(v),$(SAFE_ARG_CHARS)),$(error \
    $(v)='$(value $(v))' holds a character a shell would read: letters, digits and _ - . , = : / + only)))
# Goals reach a shell too (the lock's recipe below names them): words of the same characters.
ifneq ($(call unsafe_chars,MAKECMDGOALS,$(SAFE_ARG_CHARS)),)
  $(error goal '$(value MAKECMDGOALS)' holds a character a shell would read: see `make help` for the goals)
endif
ifneq ($(filter-out 0 1,$(words $(value SOLVER))),)
  $(error SOLVER='$(value SOLVER)' is not one path: give the solver's path without spaces)
endif
CASE_NAMES = $(patsubst cases/%/,%,$(wildcard cases/*/))
ifneq ($(call unsafe_name,case),)
  $(error case='$(value case)' is not a case name: a case is a folder cases/<name>/ with <name> made of \
      letters, digits, '_' and '-' only; the cases are: $(CASE_NAMES))
endif
ifeq ($(wildcard cases/$(case)/),)
  $(error case=$(case): no folder cases/$(case)/; the cases are: $(CASE_NAMES))
endif
# RANKS: MPI ranks of the solve (issue 15). It expands in a recipe too: checked like case= (one word of
# SAFE_NAME_CHARS), then digits only, at least 1.
RANKS ?= 1
ifneq ($(call unsafe_name,RANKS),)
  $(error RANKS='$(value RANKS)' is not a number of MPI ranks: digits only, e.g. RANKS=2)
endif
ifneq ($(strip $(filter-out 0 1 2 3 4 5 6 7 8 9,$(subst 0,0 ,$(subst 1,1 ,$(subst 2,2 ,$(subst 3,3 ,$(subst 4,4 ,\
        $(subst 5,5 ,$(subst 6,6 ,$(subst 7,7 ,$(subst 8,8 ,$(subst 9,9 ,$(RANKS)))))))))))) $(filter 0 00 000,$(RANKS))),)
  $(error RANKS=$(RANKS) is not a number of MPI ranks ≥ 1: digits only, e.g. RANKS=2)
endif
# RANKS=1000 started a thousand processes on 2 cores without a word (issue 36, item 10): at most 4
# ranks per core, as pdsolve's --threads allows at most 4 threads per core.
ifneq ($(shell [ '$(RANKS)' -le $$(( 4 * $$(nproc) )) ] 2>/dev/null || echo over),)
  $(error RANKS=$(RANKS) is more than 4 ranks per core on this machine ($(shell nproc) cores): give at most \
      RANKS=$(shell echo $$(( 4 * $$(nproc) ))), best RANKS=$(shell nproc) or fewer \
      (each rank runs OMP_NUM_THREADS threads); on a cluster, start pdsolve with the cluster's own launcher)
endif
# One rank: pdsolve alone (the serial path). More: under mpiexec; --oversubscribe lets a small machine
# run more ranks than it has cores (for tests; a cluster's launcher places ranks itself).
# Threads per rank: OMP_NUM_THREADS if it is set, else the cores shared out among the ranks (at
# least 1), passed to every rank with -x: R ranks each starting as many threads as cores would put
# R × cores threads on the cores (2 ranks × 2 spinning threads on 2 cores: 0.8–0.9 × 10⁸ bond
# updates/s at 40³ against 4.3 × 10⁸ for 2 ranks × 1 thread, docs/performance.md §7).
override RANK_THREADS := $(if $(filter-out 1,$(RANKS)),$(if $(OMP_NUM_THREADS),,$(shell t=$$(( $$(nproc) / $(RANKS) )); [ $$t -ge 1 ] || t=1; echo $$t)))
# Through pipeline/run-ranks.sh: it passes a Ctrl-C or SIGTERM to the ranks themselves, which finish
# their step and write checkpoint.bin; Open MPI's mpirun would kill them 2 s after the signal.
override MPIRUN := $(if $(filter-out 1,$(RANKS)),sh pipeline/run-ranks.sh mpiexec --oversubscribe -np $(RANKS)$(if $(RANK_THREADS), -x OMP_NUM_THREADS=$(RANK_THREADS)))

ifeq ($(origin config),undefined)
  config := $(case)
endif
ifneq ($(call unsafe_name,config),)
  $(error config='$(value config)' is not a config name: a config is a file cases/$(case)/<name>.yaml \
      with <name> made of letters, digits, '_' and '-' only)
endif
ifeq ($(wildcard cases/$(case)/$(config).yaml),)
  $(error config=$(config): no file cases/$(case)/$(config).yaml; the configs of $(case) are: \
      $(patsubst cases/$(case)/%.yaml,%,$(wildcard cases/$(case)/*.yaml)))
endif

override PY      := /usr/bin/python3
override PYTEST  := /usr/bin/python3 -m pytest
JOBS    ?= 2
override CASEDIR := cases/$(case)
override YAML    := $(CASEDIR)/$(config).yaml
override OUT     := out/$(case)$(if $(filter-out $(case),$(config)),-$(config))
SOLVER  := build/solver/pdsolve
override DEPS    := build/.deps-ok

# A case either brings its own mesh (cases/<case>/<case>.unv or .msh) or is meshed from its .geo.
override GIVEN_MESH := $(firstword $(wildcard $(CASEDIR)/$(case).unv $(CASEDIR)/$(case).msh))
override MESH       := $(if $(GIVEN_MESH),$(GIVEN_MESH),$(OUT)/mesh.msh)

PRE_SOURCES    := $(wildcard common/*.py pipeline/*.py preprocess/*.py preprocess/*/*.py)
POST_SOURCES   := $(wildcard common/*.py postprocess/*.py)
SOLVER_SOURCES := $(shell find solver -name '*.cpp' -o -name '*.hpp' -o -name 'CMakeLists.txt' 2>/dev/null)

# One writer at a time per case output folder (issue 17, item 8; issue 36, items 5-7): two
# `make case=X` in one tree drew each other's frames in progress and read half-written history rows.
# A goal that writes out/<case>/ takes flock(2) on $(OUT)/.lock, the lock peridyn's Case.run,
# validation and bench take too (common/output_lock.py), and re-runs make holding it; a second
# writer fails at once saying who holds it, or waits LOCK_WAIT seconds for it (LOCK_WAIT=600).
# The shell opens the lock as fd 9, locks it and then *becomes* the inner make (exec), which hands fd
# 9 down to the solver: so (a) the lock is held exactly as long as a process of this run lives, and
# (b) no process stands between this make and the inner one. Before, flock(1) stood there: a SIGTERM
# to this make's pid alone (`kill <pid>`) killed flock, not the run, and orphaned the solver with no
# checkpoint; a SIGTERM to the group let this make return while the solver was still writing its
# checkpoint. Now GNU make passes SIGTERM to its child and waits for it, at each level.
UNLOCKED_GOALS := help test test-asan fuzz solver deps check clean bench bench-accuracy bench-implicit validate
override LOCKED_GOALS   := $(filter-out $(UNLOCKED_GOALS),$(or $(MAKECMDGOALS),all))
LOCK_WAIT      ?= 0
override DRY_RUN        := $(findstring n,$(firstword -$(MAKEFLAGS)))# make -n writes nothing: no lock
ifneq ($(and $(LOCKED_GOALS),$(if $(PD_CASE_LOCK)$(DRY_RUN),,locked)),)
.PHONY: $(or $(MAKECMDGOALS),all) pd-case-lock
$(or $(MAKECMDGOALS),all): pd-case-lock ; @:
pd-case-lock:
	@mkdir -p '$(OUT)'
	+@exec 9>>'$(OUT)/.lock'; flock -w '$(LOCK_WAIT)' -E 75 9 || { \
	  echo "error: $(OUT)/ is in use by another run ($$(cat '$(OUT)/.lock' 2>/dev/null || echo unknown)); wait \
	for it to finish (or stop it: its Ctrl-C writes a checkpoint), or give LOCK_WAIT=<seconds> to wait" >&2; exit 75; }; \
	echo "pid $$$$, make $(MAKECMDGOALS) case=$(case) config=$(config), since $$(date +%T)" > '$(OUT)/.lock'; \
	PD_CASE_LOCK=1 PD_LOCK_FD=9 exec $(MAKE) --no-print-directory $(MAKECMDGOALS)
else
# The make this rule starts holds the lock as fd 9 (PD_LOCK_FD tells pdsolve so: it locks its output
# folder itself, io/output_lock.hpp). PD_CASE_LOCK=1 in the environment of a make run by hand would
# skip the lock: that make is refused unless fd 9 is the folder's lock and holds it. (`flock -n 9`,
# the descriptor form: with a command after it, `flock -n 9 true` locked a new file named "9".)
ifneq ($(and $(PD_CASE_LOCK),$(LOCKED_GOALS),$(if $(DRY_RUN),,check)),)
  ifneq ($(shell [ /proc/self/fd/9 -ef '$(OUT)/.lock' ] && flock -n 9 && echo held),held)
    $(error PD_CASE_LOCK is this Makefile's own (the make it starts under the lock of $(OUT)/); unset it)
  endif
endif

.PHONY: all run figures help test test-asan fuzz solver deps check clean clean-case bench bench-accuracy bench-implicit validate
.DELETE_ON_ERROR:
# `make case=X` with no goal runs the pipeline: said, since the first rule below is help's (and the
# locked make above re-runs this one with no goal either).
.DEFAULT_GOAL := all

# The list at the top of this file.
help:
	@sed -n '/^#   make /,/^# Only stale/{/^# Only stale/d;s/^# //;p}' '$(firstword $(MAKEFILE_LIST))'

all: run
run: $(OUT)/figures/.done
	@echo "results in $(OUT)/: frames.pvd (ParaView), history.csv, figures/, gmsh/results.msh (Gmsh)"
	@$(PY) -m postprocess.sizes '$(OUT)'   # what the run left on disk, by kind

deps: $(DEPS)
$(DEPS): pipeline/install-deps.sh
	sh pipeline/install-deps.sh
	@mkdir -p $(@D) && touch $@

# A case needs pdsolve alone: building every test and benchmark too was ~8 of the first
# `make case=membrane`'s 10 minutes (issue 39, item 4). test, bench and validate build the rest.
solver: $(SOLVER)
ifeq ($(SOLVER),build/solver/pdsolve)
$(SOLVER): $(SOLVER_SOURCES) | $(DEPS)
	cmake -S solver -B build/solver -DCMAKE_BUILD_TYPE=Release
	cmake --build build/solver -j$(JOBS) --target pdsolve
	@touch $@
else
# Another solver (SOLVER=…, validation's PDSOLVE) is used as it is: never built or touched here. Before,
# its rule was build/solver's, and the locked re-run of make does not get make's -o: `make
# SOLVER=/usr/bin/touch -o /usr/bin/touch …` started cmake, whose recipe ends touching $(SOLVER).
$(SOLVER):
	@echo "error: SOLVER=$(SOLVER): no such file; build that solver, or leave SOLVER unset for build/solver/pdsolve" >&2; exit 2
endif
override ALL_SOLVER_TARGETS := cmake --build build/solver -j$(JOBS)

# With the mesh at hand (given, or made by an earlier run), material and node-set names are checked
# against its physical groups too: a misspelt set is caught here, not only at preprocess.
check: | $(DEPS)
	$(PY) -m pipeline.run check '$(YAML)' $(if $(wildcard $(MESH)),'$(MESH)')

# gmsh parameters live in the .yaml; this file changes only when they do.
$(OUT)/mesh-parameters.json: $(YAML) $(PRE_SOURCES) | $(DEPS)
	$(PY) -m pipeline.run mesh-parameters '$<' '$@'

$(OUT)/mesh.msh: $(CASEDIR)/$(case).geo $(OUT)/mesh-parameters.json | $(DEPS)
	$(PY) -m pipeline.run mesh '$(YAML)' '$<' '$@'

# preprocess asks the solver for the stable step of its checks and work plan (pdsolve --physics,
# pipeline/solver_physics.py): the solver is built first, and handed over as PDSOLVE.
$(OUT)/nodes.vtu $(OUT)/case.json: export PDSOLVE := $(abspath $(SOLVER))
$(OUT)/nodes.vtu $(OUT)/case.json &: $(YAML) $(MESH) $(PRE_SOURCES) | $(DEPS) $(SOLVER)
	$(PY) -m pipeline.run preprocess '$<' '$(MESH)' '$(OUT)'

# A stamp, not history.csv, marks a finished solve: an interrupted run keeps its files (Ctrl-C and
# SIGTERM write checkpoint.bin, pipeline/formats.md §5) and the next `make` resumes it, bitwise as if
# it had never stopped, as long as the checkpoint is newer than the case, the nodes and the solver.
# exec: the solver replaces the shell, so a SIGTERM that make passes to its child reaches the solver
# (which then writes its checkpoint) instead of killing a shell and orphaning the solver.
override CHECKPOINT := $(OUT)/checkpoint.bin
$(OUT)/.solved: $(OUT)/case.json $(OUT)/nodes.vtu $(SOLVER)
	@if [ -f '$(CHECKPOINT)' ] && [ '$(CHECKPOINT)' -nt '$(OUT)/case.json' ] && [ '$(CHECKPOINT)' -nt '$(OUT)/nodes.vtu' ] \
	    && [ '$(CHECKPOINT)' -nt '$(SOLVER)' ]; then \
	  echo "$(strip $(MPIRUN) $(SOLVER)) $(OUT)/case.json --restart $(CHECKPOINT)   (resuming the interrupted run)"; \
	  exec $(MPIRUN) '$(SOLVER)' '$(OUT)/case.json' --restart '$(CHECKPOINT)'; \
	else \
	  echo "$(strip $(MPIRUN) $(SOLVER)) $(OUT)/case.json"; \
	  exec $(MPIRUN) '$(SOLVER)' '$(OUT)/case.json'; \
	fi
	@touch '$@'

$(OUT)/figures/.done: $(OUT)/.solved $(POST_SOURCES)
	$(PY) -m postprocess '$(OUT)'
	@touch '$@'

# Redraw from existing results, never solving again.
figures: | $(DEPS)
	$(PY) -m postprocess '$(OUT)'
	@touch '$(OUT)/figures/.done'

# ctest -j2 runs two tests at once, most with two OpenMP threads: four threads on two cores. With
# the default wait policy a thread that reaches a barrier first spins, on the core the other test's
# thread needs; PASSIVE makes it sleep (no result changes: the tests compare bits across thread
# counts, not across wait policies). The mpi_ranks tests set it already (solver/CMakeLists.txt).
# Measured side by side on 7 Dec 2026 with the machine's load average at 25-36 (not a quiet machine):
# `ctest -j2` of the Release tree with PASSIVE ran its 295 tests in 18 min, 35 CPU s (mpi_ranks_2
# and _3, passive before, timed out at that load); without it, 4 tests in 20 min
# (Mixed.StartedImplicitReturnsToImplicitWhenTheCrackArrests: 693 s against 5 s). Quietly the gap is
# far smaller, and not yet measured.
# Tests marked slow (tests/conftest.py) run in `make validate`, not here.
test: $(SOLVER) | $(DEPS)
	$(ALL_SOLVER_TARGETS)
	OMP_WAIT_POLICY=PASSIVE ctest --test-dir build/solver --output-on-failure -j$(JOBS)
	$(PYTEST) -q -m 'not slow' tests
	@$(MAKE) --no-print-directory test-asan

# The solver and its tests under AddressSanitizer + UBSan (+ libstdc++ assertions): any report fails
# the test that caused it (UBSan halts instead of printing and going on). -O1 without NDEBUG: at -O0
# the physics tests run 10-50 times slower under ASan (one took 11 min); -O2 compiled 2.4× slower
# than -O1 (31.6 against 13.0 CPU s for test_quasi_static.cpp), and its build was most of make
# test's time. Asserts stay on. OMP_WAIT_POLICY=PASSIVE as in make test's ctest (two tests of two
# threads on two cores).
# The pass is there for memory errors, not physics: a physics measurement that runs, on a larger
# lattice, the same functions as a smaller test that stays runs in the Release ctest only
# (ASAN_EXCLUDE). LpsTension's C3 lattices (138 s of the 247 s under ASan at -O1, 2 threads): their
# kernels are the LPS and SurfaceCorrection tests' here too. Lps.StaticTension… (a 36 × 15 × 15 LPS
# bar solved by CG; 1.1 CPU s in Release): SurfaceCorrection.ThinBarInTension…Lps solves a 30 × 6 × 6
# LPS bar by the same static_tension, with and without the correction. SurfaceCorrection.
# StaticTensionOfLpsInteriorStrains (six such solves, 3D hhb, plane strain, plane stress; 3.7 CPU s):
# the thin bar and plate tests solve with the energy correction, ForceIsTheGradient… builds the
# plane-strain factors, force and Jacobian, hhb volumes are built by the Kernel and Contact tests.
override ASAN_DIR := build/solver-asan
override ASAN_EXCLUDE_SPACE := $() $()
override ASAN_EXCLUDE := $(subst $(ASAN_EXCLUDE_SPACE),|,$(strip ^LpsTension\. \
    ^Lps\.StaticTensionGivesTheLatticesPoissonRatio$$ ^SurfaceCorrection\.StaticTensionOfLpsInteriorStrains$$))
test-asan: | $(DEPS)
	cmake -S solver -B $(ASAN_DIR) -DPD_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g"
	cmake --build $(ASAN_DIR) -j$(JOBS) --target pdsolve pd_tests
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
	    OMP_WAIT_POLICY=PASSIVE ctest --test-dir $(ASAN_DIR) --output-on-failure -j$(JOBS) -E '$(ASAN_EXCLUDE)'

# libFuzzer (clang) on the solver's readers, FUZZ_SECONDS each; a crash leaves its input in
# $(FUZZ_DIR)/artifacts/: fix the reader and add the input to solver/fuzz/regressions/<target>/.
# Then the Python case-file loader (pipeline/fuzz_case.py): a traceback or a hang leaves its input
# in the same folder as pd_fuzz_case_yaml-N.yaml: fix the loader and add a test. Last, pdsolve's
# command line (pipeline/fuzz_cli.py): every run ends with a documented exit code, no signal.
# The binary checkpoint has no dictionary: its few constants are in the seeds, and libFuzzer
# picks up the ones the reader compares against.
override FUZZ_DIR     := build/solver-fuzz
FUZZ_SECONDS ?= 60
override FUZZ_TARGETS := pd_fuzz_node_file pd_fuzz_vtu pd_fuzz_case pd_fuzz_checkpoint
fuzz: $(SOLVER) | $(DEPS)
	cmake -S solver -B $(FUZZ_DIR) -DCMAKE_CXX_COMPILER=clang++ -DPD_FUZZ=ON -DPD_BUILD_TESTS=OFF \
	    -DCMAKE_BUILD_TYPE=RelWithDebInfo
	cmake --build $(FUZZ_DIR) -j$(JOBS) --target pd_fuzz
	@mkdir -p $(FUZZ_DIR)/artifacts
	@for t in $(FUZZ_TARGETS); do \
	    case $$t in pd_fuzz_case) dict=-dict=solver/fuzz/case.dict;; pd_fuzz_checkpoint) dict=;; \
	        *) dict=-dict=solver/fuzz/vtu.dict;; esac; \
	    mkdir -p $(FUZZ_DIR)/work/$$t; \
	    echo "fuzzing $$t for $(FUZZ_SECONDS) s (log: $(FUZZ_DIR)/$$t.log)"; \
	    $(FUZZ_DIR)/fuzz/$$t -max_total_time=$(FUZZ_SECONDS) -max_len=16384 -timeout=10 -rss_limit_mb=2048 \
	        $$dict -artifact_prefix=$(FUZZ_DIR)/artifacts/$$t- \
	        $(FUZZ_DIR)/work/$$t $(FUZZ_DIR)/fuzz/corpus/$$t solver/fuzz/regressions/$$t \
	        > $(FUZZ_DIR)/$$t.log 2>&1 \
	    || { tail -n 40 $(FUZZ_DIR)/$$t.log; echo "$$t: failure, input in $(FUZZ_DIR)/artifacts/"; exit 1; }; \
	    grep '^Done' $(FUZZ_DIR)/$$t.log; \
	done
	$(PY) -m pipeline.fuzz_case --seconds $(FUZZ_SECONDS) --artifacts $(FUZZ_DIR)/artifacts
	$(PY) -m pipeline.fuzz_cli --seconds $(FUZZ_SECONDS) --solver $(SOLVER)

# A benchmark, not a timed test: bricks of 64,000, ~10⁵ and 10⁶ nodes with 1 and 2 threads
# (BENCH_SIDES to change), then the cost of output in the built cases. Prints the load average.
# LAMMPS (Debian's, with PERI) runs the same 40³ brick for comparison.
BENCH_SIDES ?= 40 46 100
# MPI rows (issue 15): 1 and 2 ranks × 1 and 2 threads beside LAMMPS on 2 ranks (bench/mpi_ranks.py).
BENCH_MPI_SIDES ?= 40 100
override BENCH_DEPS  := build/.bench-deps-ok
$(BENCH_DEPS): pipeline/install-deps.sh
	sh pipeline/install-deps.sh lammps openmpi-bin
	@mkdir -p $(@D) && touch $@
bench: $(SOLVER) | $(DEPS) $(BENCH_DEPS)
	$(ALL_SOLVER_TARGETS)
	$(PY) -m bench.speed --build build/solver --sides $(BENCH_SIDES) --out out/bench/speed.csv
	$(PY) -m bench.mpi_ranks --build build/solver --sides $(BENCH_MPI_SIDES) --out out/bench/mpi.csv

# Error against run time and force evaluations (issue 3): Verlet at several safety factors and at the
# exact limit, the adaptive step over a sweep of TOL, on a wave and on a fracture problem, against a
# Verlet run at 1/16 of the step; and (issue 13) quasi-static tension with fracture: Verlet at
# several loading rates and damping values, quasi_static and mixed, against the rate-converged
# Verlet run, ending with a speedup line; the same on cases/traction and plate_with_hole (their
# mixed.yaml on a lattice 4x coarser than the case's: ACCURACY_ARGS=--full-resolution for the case's
# own, --coarsen N for another); ACCURACY_ARGS=--quick for a smoke run (docs/accuracy.md).
ACCURACY_ARGS ?=
bench-accuracy: $(SOLVER) | $(DEPS)
	$(PY) -m bench.accuracy --solver $(SOLVER) --out out/bench $(ACCURACY_ARGS)

# Implicit dynamics (issue 13): Verlet at several steps and time.integrator: implicit over a sweep of
# implicit.tol on a drum lattice, struck (cases/drum's blow) and pushed by a smooth pulse, and on
# cases/membrane's lattice, error of u_z against a fine Verlet run versus wall time and force
# evaluations (bench/implicit_dynamics.py).
bench-implicit: $(SOLVER) | $(DEPS)
	$(PY) -m bench.implicit_dynamics --solver $(SOLVER) --out out/bench $(IMPLICIT_ARGS)

# The full cases and validation/models/ runs with quantitative checks (validation/README.md):
# out/validate/report.md, a PNG per check and convergence.png; then the end-to-end tests that
# make test leaves out (marked slow: tests/conftest.py).
validate: $(SOLVER) | $(DEPS)
	$(ALL_SOLVER_TARGETS)
	$(PY) -m validation
	$(PYTEST) -q -m slow tests

clean-case:
	rm -rf -- '$(OUT)'
clean:
	rm -rf build out

endif  # PD_CASE_LOCK
