# Orchestration only: each stage is a program, files are the interface (pipeline/formats.md).
#   make case=membrane        mesh → node cloud → solve → figures and Gmsh views, in out/membrane/
#   make figures case=X       redraw figures and Gmsh views from existing results
#   make case=X config=Y      run cases/X/Y.yaml (a variant of case X) into out/X-Y/
#   make test                 build everything and run every test
# Only stale stages rerun: an edit to the .yaml reruns preprocessing and what follows,
# a change of the gmsh parameters in the .yaml also re-meshes.

case    ?= membrane
config  ?= $(case)
PY      := /usr/bin/python3
PYTEST  := /usr/bin/python3 -m pytest
JOBS    ?= 2
CASEDIR := cases/$(case)
YAML    := $(CASEDIR)/$(config).yaml
OUT     := out/$(case)$(if $(filter-out $(case),$(config)),-$(config))
SOLVER  := build/solver/pdsolve
DEPS    := build/.deps-ok

# A case either brings its own mesh (cases/<case>/<case>.unv or .msh) or is meshed from its .geo.
GIVEN_MESH := $(firstword $(wildcard $(CASEDIR)/$(case).unv $(CASEDIR)/$(case).msh))
MESH       := $(if $(GIVEN_MESH),$(GIVEN_MESH),$(OUT)/mesh.msh)

PRE_SOURCES    := $(wildcard pipeline/*.py preprocess/*.py preprocess/*/*.py)
POST_SOURCES   := $(wildcard postprocess/*.py)
SOLVER_SOURCES := $(shell find solver -name '*.cpp' -o -name '*.hpp' -o -name 'CMakeLists.txt' 2>/dev/null)

.PHONY: all run figures test solver deps check clean clean-case
.DELETE_ON_ERROR:

all: run
run: $(OUT)/figures/.done
	@echo "results in $(OUT)/: frames.pvd (ParaView), history.csv, figures/, gmsh/results.msh (Gmsh)"

deps: $(DEPS)
$(DEPS): pipeline/install-deps.sh
	sh pipeline/install-deps.sh
	@mkdir -p $(@D) && touch $@

solver: $(SOLVER)
$(SOLVER): $(SOLVER_SOURCES) | $(DEPS)
	cmake -S solver -B build/solver -DCMAKE_BUILD_TYPE=Release
	cmake --build build/solver -j$(JOBS)
	@touch $@

check: | $(DEPS)
	$(PY) -m pipeline.run check $(YAML)

# gmsh parameters live in the .yaml; this file changes only when they do.
$(OUT)/mesh-parameters.json: $(YAML) $(PRE_SOURCES) | $(DEPS)
	$(PY) -m pipeline.run mesh-parameters $< $@

$(OUT)/mesh.msh: $(CASEDIR)/$(case).geo $(OUT)/mesh-parameters.json | $(DEPS)
	$(PY) -m pipeline.run mesh $(YAML) $< $@

$(OUT)/nodes.vtu $(OUT)/case.json &: $(YAML) $(MESH) $(PRE_SOURCES) | $(DEPS)
	$(PY) -m pipeline.run preprocess $< $(MESH) $(OUT)

$(OUT)/history.csv $(OUT)/frames.pvd &: $(OUT)/case.json $(OUT)/nodes.vtu $(SOLVER)
	$(SOLVER) $(OUT)/case.json

$(OUT)/figures/.done: $(OUT)/history.csv $(OUT)/frames.pvd $(POST_SOURCES)
	$(PY) -m postprocess $(OUT)
	@touch $@

# Redraw from existing results, never solving again.
figures: | $(DEPS)
	$(PY) -m postprocess $(OUT)
	@touch $(OUT)/figures/.done

test: $(SOLVER) | $(DEPS)
	ctest --test-dir build/solver --output-on-failure -j$(JOBS)
	$(PYTEST) -q tests

clean-case:
	rm -rf $(OUT)
clean:
	rm -rf build out
