# Thin wrapper around CMake. Every target installs missing Debian packages first.
BUILD      ?= build
BUILD_ASAN ?= build-asan
BUILD_FUZZ ?= build-fuzz
JOBS       ?= $(shell nproc)
CMAKE_FLAGS ?=
FUZZ_SECONDS ?= 60
FUZZ_SMOKE_SECONDS ?= 5

.PHONY: all deps configure demo check check-asan bench gallery fuzz fuzz-smoke clean

all: configure
	cmake --build $(BUILD) -j $(JOBS)

deps:
	@bash scripts/install-deps.sh

configure: deps
	@test -f $(BUILD)/CMakeCache.txt || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

# Generate the example scenes and sky, bake the room and the courtyard by
# night and by day (sky light), each with a view of the lit scene
# (view.png, bake --render; the room's lamp casts hard shadows, smoothed
# across texels by --supersample), filter the sky for image-based
# lighting, and place light probes in the room.
demo: all
	$(BUILD)/bin/gen_scenes examples/scenes
	$(BUILD)/bin/luxel bake examples/scenes/room.glb -o lightmaps/room --supersample 4 --render
	$(BUILD)/bin/luxel bake examples/scenes/retro.glb --texel-density 8 \
		--lights examples/retro-night.json -o lightmaps/retro --render
	$(BUILD)/bin/luxel bake examples/scenes/retro.glb --texel-density 8 \
		--lights examples/retro-day.json -o lightmaps/retro-day --render
	$(BUILD)/bin/luxel ibl examples/scenes/sky.pfm -o ibl/sky
	$(BUILD)/bin/luxel probes examples/scenes/room.glb --grid 4,3,4 -o probes/room.json
	@echo "demo: lightmaps, PNG previews, manifest.json and view.png are in lightmaps/room/, lightmaps/retro/ and lightmaps/retro-day/; the sky's irradiance, SH, specular mips and DFG table in ibl/sky/; the room's light probes in probes/room.json"

check: all
	@bash scripts/install-test-oracles.sh $(BUILD)
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

check-asan: deps
	@test -f $(BUILD_ASAN)/CMakeCache.txt || cmake -S . -B $(BUILD_ASAN) -DCMAKE_BUILD_TYPE=Debug -DLX_SANITIZE=ON
	cmake --build $(BUILD_ASAN) -j $(JOBS)
	@bash scripts/install-test-oracles.sh $(BUILD_ASAN)
	cd $(BUILD_ASAN) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ctest --output-on-failure -j $(JOBS)

bench: all
	$(BUILD)/bin/bench_bake
	@# the phases of a 4096x4096 bake of the same scene (no raw figures:
	@# they would store 268M rays)
	$(BUILD)/bin/bench_bake --only cli --cli-res 4096 --skip-raw --reps 1
	$(BUILD)/bin/bench_realtime
	$(BUILD)/bin/bench_ibl
	$(BUILD)/bin/bench_unwrap
	$(BUILD)/bin/bench_render
	$(BUILD)/bin/bench_maps
	$(BUILD)/bin/bench_horizon
	$(BUILD)/bin/bench_light2d
	$(BUILD)/bin/bench_gi
	$(BUILD)/bin/bench_denoise

# Public game-like glTF scenes (bench/gallery.sh lists them and their
# licences), downloaded at run time into $(BUILD)/gallery/cache/ and checked
# by sha256, each baked with luxel's default options and rendered:
# $(BUILD)/gallery/<scene>/view.png and $(BUILD)/gallery/summary.txt. Not
# part of make check. Offline: LUXEL_GALLERY_MIRROR=DIR (docs/gallery.md).
gallery: configure
	cmake --build $(BUILD) -j $(JOBS) --target luxel gen_scenes
	bash bench/gallery.sh --build $(BUILD)

fuzz: all
	@test -f $(BUILD_FUZZ)/CMakeCache.txt || CC=clang cmake -S . -B $(BUILD_FUZZ) -DCMAKE_BUILD_TYPE=Debug -DLX_FUZZ=ON
	cmake --build $(BUILD_FUZZ) -j $(JOBS) --target fuzzers
	@# seed the scene fuzzer with the example scenes (first byte picks .glb)
	$(BUILD)/bin/gen_scenes $(BUILD_FUZZ)/seeds
	@mkdir -p $(BUILD_FUZZ)/corpus/fuzz_scene
	@(printf '\000'; cat $(BUILD_FUZZ)/seeds/room.glb) > $(BUILD_FUZZ)/corpus/fuzz_scene/room
	@# fuzz/corpus/<name>/ holds text seeds and fuzz/<name>.dict a dictionary
	@# for fuzz_<name>, when they exist
	@for f in $(BUILD_FUZZ)/bin/fuzz_*; do \
		name=$$(basename $$f); corpus=$(BUILD_FUZZ)/corpus/$$name; mkdir -p $$corpus; \
		seeds=; test -d fuzz/corpus/$${name#fuzz_} && seeds=fuzz/corpus/$${name#fuzz_}; \
		dict=; test -f fuzz/$${name#fuzz_}.dict && dict=-dict=fuzz/$${name#fuzz_}.dict; \
		echo "== $$f"; ASAN_OPTIONS=fast_unwind_on_malloc=0 LSAN_OPTIONS=suppressions=$(CURDIR)/fuzz/lsan.supp $$f -max_total_time=$(FUZZ_SECONDS) $$dict $$corpus $$seeds || exit 1; done

# What CI runs after make check (.ci/run): every harness built and run a few
# seconds on its seeds, so a harness that no longer builds or crashes at
# once fails the run.
fuzz-smoke:
	$(MAKE) fuzz FUZZ_SECONDS=$(FUZZ_SMOKE_SECONDS)

clean:
	rm -rf $(BUILD) $(BUILD_ASAN) $(BUILD_FUZZ)
