# radiosity.h - build, demo, tests and benchmarks.
#   make demo    renders the built-in Cornell box to cornell.png (needs only a C compiler)
#   make gallery every lighting model on rows of spheres, to gallery.png
#   make lightmap  a lightmap of the Cornell box beside the box shaded by it, to lightmap.png
#   make walk    builds examples/walk.c (a camera walk through a 69k-patch scene, local matrix)
#   make learn   builds the teaching examples examples/learn_*.c into build/
#   make build/realtime  examples/realtime.c: per-frame light, E, temporal step and gather over AAVP
#   make moving-light  temporal radiosity under a moving light: PNG frames and errors in build/moving_light_frames/
#   make test    every test suite; ends with "N passed, N failed[, N skipped]"
#   make bench   writes docs/BENCHMARKS.md (long: minutes)
#   make tools   builds the command-line tools in tools/ (and tools/rad-mpi when mpicc is installed)
#   make glsl    regenerates the GLSL sources embedded in radiosity.h from tools/glsl/
#   make api     regenerates docs/api.md (the index of every public declaration) from radiosity.h
#   make report  the evaluation report (every method vs the path-traced reference, plots; the
#                real scenes when RAD_DATA_DIR holds sponza.obj) into tests/report/ (long: 15-40 min
#                on 2 shared cores); make report-quick: a small one into build/, checked
#   make clean
CC      ?= cc
CXX     ?= c++
BUILD   ?= build
WARN     = -Wall -Wextra -Wpedantic -Wshadow
CFLAGS  ?= -O2
OPENMP  := $(shell printf 'int main(void){return 0;}' | $(CC) -fopenmp -x c - -o /dev/null 2>/dev/null && echo -fopenmp)
# Embree 3 for the ray benchmark, when installed (package libembree-dev)
EMBREE  := $(shell test -f /usr/include/embree3/rtcore.h && echo -DRAD_EMBREE)
EMBREE_LIB := $(if $(EMBREE),-lembree3,)
# OpenEXR output of the tool (.exr) through tinyexr, when installed (package libtinyexr-dev)
EXR_CFLAGS := $(shell test -f /usr/include/tinyexr.h && echo -DTOOL_EXR)
EXR_LIB := $(if $(EXR_CFLAGS),-ltinyexr,)
# a folder holding the public meshes of docs/data.md, for the benchmarks and the report that
# use them (empty: they say what they skipped)
RAD_DATA_DIR ?=

.PHONY: all demo gallery lightmap walk learn moving-light test bench bench-quick tools rad-mpi fuzz clean glsl api report report-quick

all: $(BUILD)/cornell $(BUILD)/walk $(BUILD)/realtime tools

$(BUILD):
	mkdir -p $(BUILD)

$(BUILD)/cornell: examples/cornell.c examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/cornell.c -o $@ -lm

# hierarchical radiosity's links drawn over the Cornell box (examples/learn_hierarchical.c)
$(BUILD)/learn_hierarchical: examples/learn_hierarchical.c examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) -I. examples/learn_hierarchical.c -o $@ -lm

# virtual patches on the bunny in the Cornell box (needs $(RAD_DATA_DIR); --ogre for 193k triangles)
$(BUILD)/vp_bunny: examples/vp_bunny.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/vp_bunny.c -o $@ -lm

# the per-frame engine loop over virtual patches (a mesh as argument, else the Cornell box)
$(BUILD)/realtime: examples/realtime.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/realtime.c -o $@ -lm

demo: $(BUILD)/cornell
	./$(BUILD)/cornell -o cornell.png

# a lightmap of the Cornell box beside the box shaded by it (examples/lightmap.c)
$(BUILD)/lightmap: examples/lightmap.c examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/lightmap.c -o $@ -lm

lightmap: $(BUILD)/lightmap
	./$(BUILD)/lightmap -o lightmap.png

$(BUILD)/gallery: examples/gallery.c examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) -I. examples/gallery.c -o $@ -lm

gallery: $(BUILD)/gallery
	./$(BUILD)/gallery -o gallery.png

walk: $(BUILD)/walk

# the teaching examples (examples/learn_*.c): each prints a small table
LEARN = $(BUILD)/learn_formfactors $(BUILD)/learn_solvers $(BUILD)/learn_stochastic $(BUILD)/learn_vertex_light
learn: $(LEARN)
$(BUILD)/learn_%: examples/learn_%.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. $< -o $@ -lm

# temporal radiosity under a moving point light: PNG frames + per-frame error CSV (examples/moving_light.c)
$(BUILD)/moving_light: examples/moving_light.c examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/moving_light.c -o $@ -lm

moving-light: $(BUILD)/moving_light
	mkdir -p $(BUILD)/moving_light_frames
	./$(BUILD)/moving_light -o $(BUILD)/moving_light_frames/frame

# the API index: the hand-written introduction of docs/api.md kept, the rest from the header
api:
	awk -f tools/api_index.awk docs/api.md radiosity.h radiosity.h >docs/api.md.new && mv docs/api.md.new docs/api.md

test:
	CC="$(CC)" CXX="$(CXX)" BUILD="$(BUILD)" bash tests/run.sh

$(BUILD)/bench: tests/bench/bench.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -DBENCH_CFLAGS='"-std=c99 -O3 -march=native $(OPENMP)"' -I. tests/bench/bench.c -o $@ -lm

$(BUILD)/multibounce: tests/bench/multibounce.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/multibounce.c -o $@ -lm

$(BUILD)/temporal: tests/bench/temporal.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/temporal.c -o $@ -lm

$(BUILD)/shading: tests/bench/shading.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native -I. tests/bench/shading.c -o $@ -lm

# the lightmap gather: hemisphere against exact, and the 1024^2 bunny-box bake (needs $(RAD_DATA_DIR))
$(BUILD)/bench_lightmap_gather: tests/bench/lightmap_gather.c tests/bench/bench_common.h tests/bench/bench_scenes.h tools/unwrap.c tools/tool.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/lightmap_gather.c tools/unwrap.c -o $@ -lm

# lightmap timings and noise (docs/BENCHMARKS.md "Lightmaps")
$(BUILD)/bench_lightmap: tests/bench/lightmap.c tests/bench/bench_common.h tests/bench/bench_scenes.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/lightmap.c -o $@ -lm

$(BUILD)/local: tests/bench/local.c examples/rooms.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/local.c -o $@ -lm

$(BUILD)/walk: examples/walk.c examples/rooms.h examples/png_write.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) -I. examples/walk.c -o $@ -lm

$(BUILD)/probes: tests/bench/probes.c tests/bench/bench_common.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O2 $(OPENMP) -I. tests/bench/probes.c -o $@ -lm

# the real-time loop over AAVP on real meshes (tests/bench/realtime.sh; needs $(RAD_DATA_DIR))
$(BUILD)/bench_realtime: tests/bench/realtime.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/realtime.c -o $@ -lm

# lights that move over a bake (rad_baker_runtime; Sponza from $(RAD_DATA_DIR), else the Cornell box)
$(BUILD)/bench_runtime: tests/bench/runtime.c tests/bench/bench_common.h tests/bench/bench_scenes.h tools/unwrap.c tools/tool.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) -I. tests/bench/runtime.c tools/unwrap.c -o $@ -lm

# ways to mix 8 light layers on one core, side by side (x86-64 with AVX2 and F16C; not in make bench)
$(BUILD)/bench_layer_mix: tests/bench/layer_mix.c tests/bench/bench_common.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native -I. tests/bench/layer_mix.c -o $@ -lm

# the cost of saving and loading an engine-tier result (synthetic 1024 x 1024, 8 groups; not in make bench)
$(BUILD)/bench_baker_save: tests/bench/baker_save.c radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O2 -I. tests/bench/baker_save.c -o $@ -lm

$(BUILD)/rays: tests/bench/rays.c tests/bench/bench_common.h tests/bench/bench_scenes.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) -O3 -march=native $(OPENMP) $(EMBREE) -I. tests/bench/rays.c -o $@ -lm $(EMBREE_LIB)

bench: $(BUILD)/bench $(BUILD)/rays $(BUILD)/rad $(BUILD)/multibounce $(BUILD)/temporal $(BUILD)/shading $(BUILD)/local $(BUILD)/probes $(BUILD)/bench_realtime $(BUILD)/bench_lightmap $(BUILD)/bench_runtime
	./$(BUILD)/bench docs/BENCHMARKS.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) ./$(BUILD)/rays --append docs/BENCHMARKS.md
	bash tests/bench/trace.sh $(BUILD)/rad docs/BENCHMARKS.md
	bash tests/bench/methods.sh $(BUILD)/rad docs/BENCHMARKS.md
	./$(BUILD)/multibounce --append docs/BENCHMARKS.md
	./$(BUILD)/temporal --append docs/BENCHMARKS.md
	./$(BUILD)/shading --append docs/BENCHMARKS.md
	./$(BUILD)/local --append docs/BENCHMARKS.md
	./$(BUILD)/probes --append docs/BENCHMARKS.md
	./$(BUILD)/bench_lightmap --append docs/BENCHMARKS.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tests/bench/realtime.sh $(BUILD) docs/BENCHMARKS.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tests/bench/sponza.sh $(BUILD)/rad docs/BENCHMARKS.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) ./$(BUILD)/bench_runtime --append docs/BENCHMARKS.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tests/bench/scenes.sh $(BUILD)/rad docs/BENCHMARKS.md

bench-quick: $(BUILD)/bench $(BUILD)/rays $(BUILD)/rad $(BUILD)/multibounce $(BUILD)/temporal $(BUILD)/shading $(BUILD)/local $(BUILD)/probes $(BUILD)/bench_realtime
	./$(BUILD)/bench --quick $(BUILD)/BENCHMARKS-quick.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) ./$(BUILD)/rays --append $(BUILD)/BENCHMARKS-quick.md
	bash tests/bench/methods.sh $(BUILD)/rad $(BUILD)/BENCHMARKS-quick.md --quick
	./$(BUILD)/multibounce --quick --append $(BUILD)/BENCHMARKS-quick.md
	./$(BUILD)/temporal --quick --append $(BUILD)/BENCHMARKS-quick.md
	./$(BUILD)/shading --quick --append $(BUILD)/BENCHMARKS-quick.md
	./$(BUILD)/local --quick --append $(BUILD)/BENCHMARKS-quick.md
	./$(BUILD)/probes --quick --append $(BUILD)/BENCHMARKS-quick.md
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tests/bench/realtime.sh --quick $(BUILD) $(BUILD)/BENCHMARKS-quick.md

# the MPI driver of the distributed bake (docs/distributed.md), when OpenMPI is installed
# (Debian libopenmpi-dev openmpi-bin): the tool's sources but main.c, with tools/mpi/rad_mpi.c's main
MPICC   ?= mpicc
HAVE_MPICC := $(shell command -v $(MPICC) 2>/dev/null)
tools: $(BUILD)/rad $(if $(HAVE_MPICC),$(BUILD)/rad-mpi)

rad-mpi: $(BUILD)/rad-mpi

$(BUILD)/rad-mpi: tools/mpi/rad_mpi.c $(wildcard tools/*.c) tools/tool.h radiosity.h | $(BUILD)
	$(MPICC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) $(EXR_CFLAGS) -I. $(filter-out tools/main.c,$(wildcard tools/*.c)) tools/mpi/rad_mpi.c -o $@ -lassimp $(EXR_LIB) -lm
	cp $@ tools/rad-mpi

# the tool needs assimp (scene import) and stb (images): Debian libassimp-dev libstb-dev;
# tinyexr (libtinyexr-dev) is optional: without it .exr outputs fail with a message
$(BUILD)/rad: $(wildcard tools/*.c) tools/tool.h radiosity.h | $(BUILD)
	$(CC) -std=c99 $(WARN) $(CFLAGS) $(OPENMP) $(EXR_CFLAGS) -I. tools/*.c -o $@ -lassimp $(EXR_LIB) -lm
	cp $@ tools/rad

# the evaluation report (tools/report.sh): full quality into tests/report/ (committed), or
# quick into build/report-quick/ with every table cell and image checked (tests/run.sh runs it)
report: $(BUILD)/rad $(BUILD)/temporal $(BUILD)/bench_realtime
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tools/report.sh --rad $(BUILD)/rad --temporal-bench $(BUILD)/temporal --realtime-bench $(BUILD)/bench_realtime

report-quick: $(BUILD)/rad $(BUILD)/temporal
	RAD_DATA_DIR=$(RAD_DATA_DIR) bash tools/report.sh --quick --out $(BUILD)/report-quick --rad $(BUILD)/rad --temporal-bench $(BUILD)/temporal

# libFuzzer harnesses (clang with libclang-rt-14-dev), one per loader: FUZZ_SECONDS per
# fuzzer, every harness run even when one fails (the target fails at the end); the corpora
# grow in $(BUILD)/fuzz/corpus/<harness>, crash inputs land in $(BUILD)/fuzz/<harness>-crash-*.
# One harness: make fuzz FUZZ_HARNESSES=stream
FUZZ_SECONDS ?= 300
FUZZ_CC ?= clang
FUZZ_HARNESSES ?= container scene stream multibounce temporal vp
fuzz: | $(BUILD)
	mkdir -p $(addprefix $(BUILD)/fuzz/corpus/,container scene stream multibounce temporal vp)
	$(CC) -std=c99 -O2 -I. tests/fuzz/make_corpus.c -o $(BUILD)/fuzz/make_corpus -lm
	./$(BUILD)/fuzz/make_corpus $(BUILD)/fuzz/corpus
	failed=""; for f in $(FUZZ_HARNESSES); do \
	    if $(FUZZ_CC) -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. tests/fuzz/fuzz_$$f.c -o $(BUILD)/fuzz/fuzz_$$f -lm && \
	       TMPDIR=$(BUILD)/fuzz ./$(BUILD)/fuzz/fuzz_$$f -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 -artifact_prefix=$(BUILD)/fuzz/$$f- $(BUILD)/fuzz/corpus/$$f; \
	    then :; else failed="$$failed $$f"; fi; \
	done; \
	if [ -n "$$failed" ]; then echo "fuzz: failed:$$failed"; exit 1; fi

clean:
	rm -rf $(BUILD) cornell.png gallery.png lightmap.png tools/rad tools/rad-mpi

# the GLSL kernels: tools/glsl/*.comp are the canonical sources, embedded into radiosity.h
$(BUILD)/glsl_embed: tools/glsl/embed.c | $(BUILD)
	$(CC) -std=c99 $(WARN) -O2 tools/glsl/embed.c -o $@

glsl: $(BUILD)/glsl_embed
	./$(BUILD)/glsl_embed radiosity.h
