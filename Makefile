# jdem — build, test and run.  `make demo` and `make test` are the whole set-up on a fresh
# Debian machine: both install what is missing (make deps) before they build.
#
#   make            build/jdem and build/liggghts-jdem
#   make deps       install the Debian packages the project needs (as root), else print the command
#   make test       unit tests (also under ASan+UBSan), engine tests, Chung–Ooi checks, cross-engine
#   make demo       build and run the eight Chung–Ooi tests, the stability suite and a short
#                   Chapter 4 mixing fill; reports in out/chung_ooi/report.md and
#                   out/stability/report.md, pictures in out/mixing/demo/
#   make chung-ooi  the Chung–Ooi runs and report only (no dependency check)
#   make accuracy   error against run time, three engines; report in out/accuracy/report.md
#   make stability  the stability suite (reference_runs/stability/, both engines, 1x and 2x/5x/10x
#                   the guard's dt); out/stability/report.md and summary.json
#   make bonds      the parallel-bond checks and bench figure; out/bonds/summary.json

SHELL := /bin/bash
PY    := /usr/bin/python3
# The repository root is the module path of every Python recipe: scripts/ and tests/ are
# packages imported as scripts.NAME and tests.SUITE.NAME (scripts/__init__.py).
export PYTHONPATH := $(CURDIR)
CC    := gcc
CXX   := mpicxx

DEB_PACKAGES := gcc g++ make pkg-config clang libclang-rt-14-dev libyaml-dev libhdf5-dev libcmocka-dev \
                python3-numpy python3-scipy python3-h5py python3-matplotlib python3-yaml liggghts-doc \
                liggghts libliggghts-dev mpi-default-dev mpi-default-bin libadmesh-dev

VERSION  := 0.1.0
# The source a binary is built from, in its trajectories' creator version ("0.1.0+<commit>",
# "-dirty" with uncommitted changes to tracked files), so that every campaign result names the
# code that computed it.  build/source_commit.h is rewritten only when that changes.
SOURCE_COMMIT := $(shell git describe --always --dirty --abbrev=7 2>/dev/null || echo unknown)
WARN     := -Wall -Wextra -Werror
PKG_CFLAGS := $(shell pkg-config --cflags yaml-0.1 hdf5 libadmesh 2>/dev/null)
PKG_LIBS   := $(shell pkg-config --libs yaml-0.1 hdf5 libadmesh 2>/dev/null) -lm
# Code generation, the same for both engines.  -O3 with the host's vector units: the pair loop
# evaluates the contact law in SIMD lanes (stepper/forces.c).  -fno-trapping-math lets the
# vectoriser compute both sides of the law's selects (e.g. a division in a lane whose result is
# not selected); no floating-point trap is ever enabled, and every result is the IEEE one
# (no fast-math, no contraction: -ffp-contract=off), so the engines agree bit for bit per contact.
# Valgrind does not decode AVX-512: profile a build made with ARCH=-march=x86-64-v3.
ARCH     ?= -march=native
OPT      := -O3 $(ARCH) -fno-trapping-math -ffp-contract=off
CFLAGS   := -std=c11 $(OPT) -g $(WARN) -D_POSIX_C_SOURCE=200809L -DJDEM_VERSION=\"$(VERSION)\" \
            -Ikernel -Iio -Istepper -Ibuild $(PKG_CFLAGS)
# The sanitizer build compiles the force loops once, with the feature set as a run-time value
# (stepper/forces.c, JD_ONE_FORCE_LOOP): it checks the code, not its speed, so one inlined copy
# of the law under ASan+UBSan instead of one per law set (build times: docs/performance.md).
SANFLAGS := -O1 -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer \
            -DJD_ONE_FORCE_LOOP
# OpenMP threads in the standalone engine's force and integration loops (stepper/ only: the
# kernel and the H5MD writer stay free of it, and clang's fuzz build needs no OpenMP runtime).
# Threads: `jdem run --threads N` or OMP_NUM_THREADS (docs/scenes.md, "Threads").
# -fno-math-errno: sqrt compiles to the instruction alone (no errno branch); the results are
# the same bits (sqrt is correctly rounded either way), and the stepper never reads errno after
# a math function.
OMPFLAGS := -fopenmp -fno-math-errno

KERNEL_SRC  := $(wildcard kernel/*.c)
IO_SRC      := $(wildcard io/*.c)
STEPPER_SRC := $(wildcard stepper/*.c)
# the scene reader and what it calls for dt: auto: the guard, the kernel, the bonds' bound (whose file
# also writes bond frames: io/)
SCENE_SRC   := $(wildcard stepper/scene*.c) stepper/guard.c stepper/bonds.c $(KERNEL_SRC) $(IO_SRC)
PLUGIN_SRC  := $(wildcard liggghts_plugin/*.cpp)
UNIT_SRC    := $(wildcard tests/unit/*.c) stepper/hugepages.c # and the engine's block allocator
HEADERS     := $(wildcard kernel/*.h io/*.h stepper/*.h)

# ParaView for the paraview suite only (about 440 MB installed): kept out of `make deps` so that
# `make demo` stays light; `make test` installs it (a fresh machine's `make test` runs every suite).
PARAVIEW_PACKAGES := paraview python3-paraview xvfb xauth

.PHONY: all deps paraview-deps test demo chung-ooi stability unit clean
all: build/jdem build/liggghts-jdem
-include $(shell find build -name '*.d' 2>/dev/null)

# ---------------------------------------------------------------------------------------------
# Dependencies (Debian only)
deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; \
	  done); \
	if [ -z "$$missing" ]; then echo "deps: all Debian packages present"; exit 0; fi; \
	cmd="apt-get install -y --no-install-recommends $$(echo $$missing)"; \
	if [ "$$(id -u)" = 0 ]; then \
	  echo "deps: installing $$(echo $$missing)"; \
	  export DEBIAN_FRONTEND=noninteractive; apt-get update -qq && $$cmd -qq >/dev/null; \
	else echo "deps: missing packages; run as root:  apt-get update && $$cmd"; exit 1; fi

paraview-deps:
	@$(MAKE) --no-print-directory deps DEB_PACKAGES="$(PARAVIEW_PACKAGES)"

# ---------------------------------------------------------------------------------------------
# Standalone engine (C11) and its sanitizer twin
# Every object lists the headers it includes in a .d file next to it (-MMD -MP), read back below:
# a changed header rebuilds exactly the objects that include it.
DEPFLAGS := -MMD -MP
build/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(DEPFLAGS) -c $< -o $@
build/obj/stepper/%.o: stepper/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(OMPFLAGS) $(DEPFLAGS) -c $< -o $@

build/san/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SANFLAGS) $(DEPFLAGS) -c $< -o $@
build/san/stepper/%.o: stepper/%.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(OMPFLAGS) $(SANFLAGS) $(DEPFLAGS) -c $< -o $@

# The bond loop is scalar code (a bond per iteration); GCC's straight-line vectoriser packs its
# 3-vectors into 512-bit registers with shuffles, which made it slower (docs/performance.md).
# The same bits: the vectoriser never reorders floating-point operations here (no fast-math).
build/obj/stepper/bonds.o: CFLAGS += -fno-tree-slp-vectorize

build/source_commit.h: FORCE
	@mkdir -p build
	@echo '#define JDEM_SOURCE_COMMIT "$(SOURCE_COMMIT)"' > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi
.PHONY: FORCE
FORCE:
build/obj/stepper/main.o build/san/stepper/main.o build/plugin/liggghts_plugin/dump_h5md_jdem.o: \
    build/source_commit.h

build/jdem: $(patsubst %.c,build/obj/%.o,$(KERNEL_SRC) $(IO_SRC) $(STEPPER_SRC))
	$(CC) $(CFLAGS) $(OMPFLAGS) $^ -o $@ $(PKG_LIBS)

build/san/jdem: $(patsubst %.c,build/san/%.o,$(KERNEL_SRC) $(IO_SRC) $(STEPPER_SRC))
	$(CC) $(CFLAGS) $(OMPFLAGS) $(SANFLAGS) $^ -o $@ $(PKG_LIBS)

# ---------------------------------------------------------------------------------------------
# LIGGGHTS plugin: Debian's libliggghts + our styles; the kernel and the H5MD writer are the same
# C objects as in the stepper (compiled position-independent), and the same code generation (OPT).
PLUGIN_CXXFLAGS := -std=c++11 $(OPT) -g -Wall -Wextra -Werror -Wno-unused-parameter -fPIC \
                   -DOMPI_SKIP_MPICXX -DJDEM_VERSION=\"$(VERSION)\" -Ikernel -Iio -Ibuild -isystem /usr/include/liggghts $(PKG_CFLAGS)
build/pic/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fPIC $(DEPFLAGS) -c $< -o $@
build/plugin/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(PLUGIN_CXXFLAGS) $(DEPFLAGS) -c $< -o $@
# The bond loop, as in the stepper (build/obj/stepper/bonds.o; docs/performance.md).
build/plugin/liggghts_plugin/fix_bond_jiang.o: PLUGIN_CXXFLAGS += -fno-tree-slp-vectorize
# The pair style's SIMD lanes (pair_gran_jiang_lanes.h): sqrt as the instruction alone, as in the
# stepper (OMPFLAGS), or the lane loop keeps a libm call per lane and is not vectorised.  The same
# bits (sqrt is correctly rounded either way); the pair style never reads errno.
build/plugin/liggghts_plugin/pair_gran_jiang.o: PLUGIN_CXXFLAGS += -fno-math-errno
build/liggghts-jdem: $(patsubst %.cpp,build/plugin/%.o,$(PLUGIN_SRC)) \
                     $(patsubst %.c,build/pic/%.o,$(KERNEL_SRC) $(IO_SRC))
	$(CXX) $^ -o $@ -lliggghts $(PKG_LIBS) -ldl

# ---------------------------------------------------------------------------------------------
# The test programs link the engine's own objects (compiled once, side by side under make -j)
# with their test files: the unit tests of the kernel (cmocka) and the scene reader's test program
# (malformed scenes with their exact messages; round trips), plain and sanitized.
UNIT_OBJ  := $(patsubst %.c,%.o,$(UNIT_SRC) $(KERNEL_SRC) $(IO_SRC))
SCENE_OBJ := $(patsubst %.c,%.o,tests/engine/scene_check.c $(SCENE_SRC))
build/obj/tests/unit/%.o build/san/tests/unit/%.o: CFLAGS += -Itests/unit
build/test_unit: $(addprefix build/obj/,$(UNIT_OBJ))
	$(CC) $(CFLAGS) $(OMPFLAGS) $^ -o $@ $(PKG_LIBS) -lcmocka
build/san/test_unit: $(addprefix build/san/,$(UNIT_OBJ))
	$(CC) $(CFLAGS) $(OMPFLAGS) $(SANFLAGS) $^ -o $@ $(PKG_LIBS) -lcmocka
build/scene_check: $(addprefix build/obj/,$(SCENE_OBJ))
	$(CC) $(CFLAGS) $(OMPFLAGS) $^ -o $@ $(PKG_LIBS)
build/san/scene_check: $(addprefix build/san/,$(SCENE_OBJ))
	$(CC) $(CFLAGS) $(OMPFLAGS) $(SANFLAGS) $^ -o $@ $(PKG_LIBS)

unit: build/test_unit build/san/test_unit
	build/test_unit
	build/san/test_unit

# ---------------------------------------------------------------------------------------------
# The suites.  tests/run_tests.py runs every check and prints "N passed, N failed".
# Both the build and the suites use every core this process may run on (CI: 2); the suites run
# side by side, a suite with 2 MPI ranks alone on 2 cores (tests/run_tests.py).
# JDEM_TEST_JOBS=N sets the cores of both.
JDEM_TEST_JOBS ?= $(shell nproc)
export JDEM_TEST_JOBS
test: deps paraview-deps
	$(MAKE) -j$(JDEM_TEST_JOBS) all build/san/jdem build/test_unit build/san/test_unit build/scene_check \
	    build/san/scene_check
	$(PY) tests/run_tests.py

chung-ooi: build/jdem build/liggghts-jdem
	$(PY) scripts/chung_ooi.py run --engines jdem,liggghts --out out/chung_ooi

stability: build/jdem build/liggghts-jdem
	$(PY) scripts/stability.py --out out/stability

# The first run of a new machine: the Debian packages, the build on every core (JDEM_TEST_JOBS),
# the Chung–Ooi tests, the stability suite and a short Ch. 4 fill (README).
demo: deps
	$(MAKE) -j$(JDEM_TEST_JOBS) all
	$(MAKE) chung-ooi
	$(MAKE) stability
	$(MAKE) mixing-demo
	@echo "reports: out/chung_ooi/report.md out/stability/report.md; picture: out/mixing/demo/front_t$(MIXING_DEMO_TIME).png"

# A short Model 2 fill of the Chapter 4 campaign in jdem (the sections that start within
# MIXING_DEMO_TIME seconds, at the seed's dt, forced as the campaign runs it) and its front view.
MIXING_DEMO_TIME ?= 2
MIXING_DEMO_SECTIONS ?= 8
.PHONY: mixing-demo
mixing-demo: build/jdem
	@mkdir -p out/mixing/demo
	$(PY) reference_runs/mixing/ch4/generate.py fill --case model2 --sections $(MIXING_DEMO_SECTIONS) \
	    --end-time $(MIXING_DEMO_TIME) -o out/mixing/demo/model2_fill.yaml
	build/jdem run out/mixing/demo/model2_fill.yaml -o out/mixing/demo/model2_fill.h5 --force
	$(PY) scripts/mixing_views.py out/mixing/demo/model2_fill.h5 -o out/mixing/demo \
	    --times 1,2,final --views front

# Performance benchmark (reference_runs/bench/README.md): settled beds, 3 engines, medians of 3.
#   make bench [BENCH_SIZES=5k,20k,80k,320k,1M] [BENCH_VARIANTS=soft_mono,soft_mono_bonded]
#              [BENCH_REPEATS=3]                              report: out/bench/report.md
# 80k, 320k and 1M are tiled from the 20k bed; every variant at every size is a long run
# (durations: docs/performance.md).
.PHONY: bench
bench: all
	$(PY) scripts/bench.py $(if $(BENCH_SIZES),--sizes $(BENCH_SIZES)) $(if $(BENCH_REPEATS),--repeats $(BENCH_REPEATS)) \
	    $(if $(BENCH_VARIANTS),--variants $(BENCH_VARIANTS))
	$(PY) scripts/bond_bench.py --engines jdem,liggghts-jdem --out out/bench/bonds $(if $(BENCH_REPEATS),--repeats $(BENCH_REPEATS))

# Parallel bonds: every check of scripts/bond_checks.py in full length, in the engines
# of BONDS_ENGINES (jdem, liggghts-jdem), plus the ns-per-bond-step figure of bond_bench.py;
# records in out/bonds/summary.json.  `make test` runs the same checks shortened (--quick).
BONDS_ENGINES ?= jdem,liggghts-jdem
.PHONY: bonds
bonds: all
	$(PY) scripts/bond_bench.py --engines $(BONDS_ENGINES) --out out/bonds
	$(PY) scripts/bond_checks.py --engines $(BONDS_ENGINES) --out out/bonds --bench out/bonds/bench.json

# Del Cid's (2015) MEPA drop test (her Figs 4.5 and 4.6), n = 1 and 3/2, in both engines: the
# force-overlap traces against the law's branches.  Report: out/mepa/report.md; its committed
# copy: reference_runs/mepa/results/.
.PHONY: mepa
mepa: all
	$(PY) scripts/mepa_drop.py --out out/mepa --results reference_runs/mepa/results

# Del Cid's (2015) MEPA sandpiles, her Table 4.3 (docs/sandpile.md): per engine and case (dry and
# kc = 1.07e7, mu_r = 0.1 ... 0.6) the settling, the discharge scene and the discharge, the
# resumable units of scripts/sandpile/plan.py with progress and an ETA; finished units are skipped.
#   make sandpile [CASE=kc107_mur04] [ENGINE=jdem|liggghts-jdem] [UNIT=jdem/dry_mur01/fill] [LIST=1]
#                 [RERUN=1]   outputs: out/sandpile/ENGINE/CASE/{fill,discharge}.h5
# Then `make sandpile-report`: Table 4.3 seed | jdem | liggghts-jdem with the run times,
# out/sandpile/report.md and its committed copy reference_runs/sandpile/results/.
SANDPILE_ENGINE = $(or $(ENGINE),$(firstword $(subst /, ,$(UNIT))))
.PHONY: sandpile sandpile-report
sandpile: $(if $(filter jdem,$(SANDPILE_ENGINE)),build/jdem,build/jdem build/liggghts-jdem)
	$(PY) scripts/campaign.py scripts/sandpile/plan.py $(if $(CASE),--model $(CASE)) \
	    $(if $(ENGINE),--engine $(ENGINE)) $(if $(UNIT),--unit $(UNIT)) $(if $(LIST),--list) \
	    $(if $(RERUN),--rerun-committed)

sandpile-report: build/jdem
	$(PY) -m scripts.sandpile.report

# Error against run time: Chung–Ooi tests 1, 3, 4 and a settling bed, dt swept over
# factors of the time-step guard's dt, in jdem, liggghts-jdem and LIGGGHTS hertz/history; timings
# medians of ACCURACY_REPEATS (default 3); its duration: docs/performance.md.  Report:
# out/accuracy/report.md
.PHONY: accuracy
accuracy: all
	$(PY) scripts/accuracy.py run $(if $(ACCURACY_REPEATS),--repeats $(ACCURACY_REPEATS))

# Jiang's Chapter 4 mixing campaign (docs/mixing.md §4): the resumable units of
# scripts/mixing/plan_ch4.py, with progress and an ETA; finished units are skipped.
#   make mixing [MODEL=model2] [ENGINE=jdem|liggghts-jdem|cross] [UNIT=jdem/model2/fill1]
#               [DT=seed|guard|half] [NP=2] [LIST=1] [RERUN=1]  outputs: out/mixing/ch4*/ENGINE/MODEL/
# A unit whose result is committed (reference_runs/mixing/ch4/results/) is skipped unless a unit
# that runs reads its outputs; RERUN=1 runs the committed units again (scripts/campaign.py).
# (NP: the MPI ranks of each liggghts-jdem fill)
# (ENGINE=cross: the cross-engine horizons, cross/modelM/horizon, which run both engines)
# The engine's binary only when the selection names one engine (ENGINE=, or UNIT=ENGINE/...).
MIXING_ENGINE = $(or $(ENGINE),$(firstword $(subst /, ,$(UNIT))))
.PHONY: mixing
mixing: $(if $(filter jdem,$(MIXING_ENGINE)),build/jdem,$(if $(MIXING_ENGINE),build/liggghts-jdem build/jdem,all))
	$(PY) scripts/campaign.py scripts/mixing/plan_ch4.py $(if $(MODEL),--model $(MODEL)) \
	    $(if $(ENGINE),--engine $(ENGINE)) $(if $(UNIT),--unit $(UNIT)) $(if $(LIST),--list) \
	    $(if $(RERUN),--rerun-committed) \
	    $(if $(DT)$(NP),--) $(if $(DT),--dt $(DT)) $(if $(NP),--ranks $(NP))

# Jiang's Chapter 5 bonded-block campaign (docs/mixing.md §11): the 18 fills of
# reference_runs/mixing/ch5/models.yaml (Groups 1-3 x Models 1-6) and Chapter 6's two rigid-cement
# fills (rigid_model1, rigid_model3) in both engines, the resumable units of
# scripts/mixing/plan_ch5.py, and the realisations of a few fills (fill_jitterK: the run-to-run
# spread of whole fills).  outputs: out/mixing/ch5/ENGINE/groupG_modelM/fill.h5
#   make mixing-bonded [MODEL=group2_model3] [ENGINE=jdem|liggghts-jdem|cross] [UNIT=...] [NP=2] [LIST=1]
#                      [RERUN=1]   (committed units: as `make mixing`)
# (ENGINE=cross: the cross-engine horizons and first breaks, cross/groupG_modelM/horizon, and
#  the jdem runs with the stream shifted that measure their spread, cross/groupG_modelM/jitterK)
.PHONY: mixing-bonded
mixing-bonded: $(if $(filter jdem,$(MIXING_ENGINE)),build/jdem,build/liggghts-jdem build/jdem)
	$(PY) scripts/campaign.py scripts/mixing/plan_ch5.py $(if $(MODEL),--model $(MODEL)) \
	    $(if $(ENGINE),--engine $(ENGINE)) $(if $(UNIT),--unit $(UNIT)) $(if $(LIST),--list) \
	    $(if $(RERUN),--rerun-committed) \
	    $(if $(NP),-- --ranks $(NP))

# The seed's Fig. 5-4, the repeated section in 3D in both engines, drawn by ParaView from each
# trajectory's sidecar: reference_runs/mixing/ch5/results/fig5-4.png (needs `make paraview-deps`).
.PHONY: mixing-bonded-section
mixing-bonded-section: build/jdem build/liggghts-jdem
	$(PY) -m scripts.mixing.section_ch5

# Table 5-3 (phi_v at the middle clip) and the breakage of the finished Ch. 5 fills, seed | jdem |
# liggghts-jdem: out/mixing/ch5/report.md and reference_runs/mixing/ch5/results/; first the
# cross-engine horizons and first breaks (reference_runs/mixing/ch5/results/horizon/).
.PHONY: mixing-bonded-report
mixing-bonded-report:
	$(PY) -m scripts.mixing.horizon_ch5 summary --results reference_runs/mixing/ch5/results/horizon
	$(PY) -m scripts.mixing.report_ch5

# The tables of the finished units, seed | jdem | liggghts-jdem (Tables 4-3...4-5, the mixing
# parameters, run times) and Figs 4-11/4-12: out/mixing/ch4/report.md, summary.json and
# fig4-1N_ENGINE.png, and the committed copy in reference_runs/mixing/ch4/results/; a result not
# under out/ is taken from the committed summary.json with the commit it came from.  First the
# cross-engine horizons' table and plot (reference_runs/mixing/ch4/results/horizon/).
# The fill's speed in jdem, liggghts-jdem and stock LIGGGHTS (1 and 2 cores each), measured in
# one run: out/mixing/speed/report.md and summary.json (docs/mixing.md §10).
.PHONY: mixing-speed
mixing-speed: all
	$(PY) -m scripts.mixing.speed_ch4 $(if $(SPEED_TIME),--end-time $(SPEED_TIME)) $(if $(SPEED_ROUNDS),--rounds $(SPEED_ROUNDS)) \
	    $(if $(SPEED_ONLY),--only $(SPEED_ONLY))

.PHONY: mixing-report
# DT=guard|half: first that variant's report (reference_runs/mixing/ch4_dt_DT/results/), which the
# main report's "error against run time" table reads
mixing-report:
	$(if $(filter-out guard half,$(DT)),$(error DT=$(DT): valid for mixing-report: guard or half (the seed's dt is the main report)))
	$(if $(filter guard half,$(DT)),$(PY) scripts/mixing/report_ch4.py --out out/mixing/ch4_dt_$(DT) \
	    --results reference_runs/mixing/ch4_dt_$(DT)/results)
	$(PY) scripts/mixing/horizon_ch4.py summary --results reference_runs/mixing/ch4/results/horizon
	$(PY) scripts/mixing/report_ch4.py --results reference_runs/mixing/ch4/results

clean:
	rm -rf build out

# ---------------------------------------------------------------------------------------------
# Fuzzing the scene reader with libFuzzer (clang): `make fuzz [FUZZ_SECONDS=600]`.  The seed
# corpus tests/fuzz/corpus/ is read only; inputs that grow coverage collect in build/fuzz/corpus
# (fold the useful ones back with `build/fuzz_scene -merge=1 tests/fuzz/corpus build/fuzz/corpus`)
# and a crashing input is written to build/fuzz/ (the run then fails).  Then the LIGGGHTS side,
# FUZZ_SECONDS each: the deck generator against hostile resolved scenes (tests/fuzz/fuzz_deck.py)
# and our styles' argument parsers in liggghts-jdem (tests/fuzz/fuzz_styles.py); their failing
# inputs go to build/fuzz/ too.
FUZZ_SECONDS ?= 60
.PHONY: fuzz
build/fuzz_scene: tests/fuzz/fuzz_scene.c $(SCENE_SRC) $(HEADERS)
	@mkdir -p build
	clang $(CFLAGS) -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	    tests/fuzz/fuzz_scene.c $(SCENE_SRC) -o $@ $(PKG_LIBS)
fuzz: build/fuzz_scene build/jdem build/liggghts-jdem
	@mkdir -p build/fuzz/corpus
	build/fuzz_scene -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 \
	    -dict=tests/fuzz/scene.dict -artifact_prefix=build/fuzz/ build/fuzz/corpus tests/fuzz/corpus
	$(PY) tests/fuzz/fuzz_deck.py --seconds $(FUZZ_SECONDS) --out build/fuzz
	$(PY) tests/fuzz/fuzz_styles.py --seconds $(FUZZ_SECONDS) --out build/fuzz
