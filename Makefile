# maskline: the one build entry. See README.md.
#   make          host build into build/ (library, CLI, tools)
#   make test     every test, sanitized; last line "N passed, N failed"
#   make demo     render the bundled scene (and 2CylinderEngine when installed) into out/
#   make tables   regenerate tables/ from tools/maskgen
#   make fuzz     run the blob-reader and glTF-import fuzzers for a minute each
#   make bench    instruction counts (callgrind) for both renderers against a z-buffer baseline
#   make bench-board  instructions a frame, flash and RAM of the firmware images under QEMU
#   make firmware Cortex-M firmware images for QEMU boards into build/firmware/ (docs/firmware.md)

BUILD   ?= build
CXX     ?= g++
CLANGXX ?= clang++
# Mask-table interval count per side (tables/ holds the generated arrays for this k).
MASK_K  ?= 16

WARN      := -Wall -Wextra -Werror
CXXSTD    := -std=c++17
INCLUDES  := -Isrc -I.
# src/ runs on the board: integer-only (a float is a compile error), no exceptions, no RTTI. No SLP
# vectorizer on the host: with -mgeneral-regs-only GCC 12 packs pairs of 32-bit operations into one
# 64-bit register and got a pair of __builtin_ctz wrong there (docs/design.md); it gains nothing here.
CORE_FLAGS := $(CXXSTD) $(WARN) $(INCLUDES) -mgeneral-regs-only -fno-exceptions -fno-rtti -fno-tree-slp-vectorize
HOST_FLAGS := $(CXXSTD) $(WARN) $(INCLUDES)
OPT       := -O2 -g
SAN       := -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

CORE_SRC  := $(shell find src tables -name '*.cpp' 2>/dev/null | sort)
SCENEC_SRC:= $(shell find tools/scenec -name '*.cpp' 2>/dev/null | sort)
# Host code: the CLI's pieces, the panel drivers (shared with firmware) and the Linux display code.
HOST_SRC  := $(filter-out platform/host/main.cpp,$(shell find platform/host platform/panels platform/linux -name '*.cpp' 2>/dev/null | sort))
TEST_SRC  := $(shell find tests -name '*.cpp' -not -path 'tests/fuzz/*' -not -path 'tests/qemu-fbdev/*' 2>/dev/null | sort)
MASKGEN_SRC := $(shell find tools/maskgen -name '*.cpp' 2>/dev/null | sort)
BENCH_SRC := $(shell find tools/bench -name '*.cpp' -not -path 'tools/bench/sort/*' 2>/dev/null | sort)

HOST_LIBS := -lpng -lgpiod

# ---- object lists: release (build/obj/) and sanitized (build/san/obj/; build/san/ holds the binaries) ----
rel = $(patsubst %.cpp,$(BUILD)/obj/%.o,$(1))
san = $(patsubst %.cpp,$(BUILD)/san/obj/%.o,$(1))

CORE_OBJ   := $(call rel,$(CORE_SRC))
SCENEC_OBJ := $(call rel,$(SCENEC_SRC))
HOST_OBJ   := $(call rel,$(HOST_SRC))
CORE_SOBJ  := $(call san,$(CORE_SRC))
SCENEC_SOBJ:= $(call san,$(SCENEC_SRC))
HOST_SOBJ  := $(call san,$(HOST_SRC))
TEST_SOBJ  := $(call san,$(TEST_SRC))

.PHONY: all test demo tables fuzz bench bench-board clean bootstrap
# Every entry target installs missing packages first, then builds in a sub-make: with -j the compiles
# must not start before the headers they need are installed. Parallel by default (2 cores).
ifeq ($(MAKELEVEL),0)
MAKEFLAGS += -j2
endif

all: bootstrap
	@$(MAKE) --no-print-directory $(BUILD)/maskline $(BUILD)/maskgen

bootstrap:
	@bash tools/bootstrap.sh

# core: both builds use CORE_FLAGS
$(BUILD)/obj/src/%.o: src/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CORE_FLAGS) $(OPT) -MMD -MP -c $< -o $@
$(BUILD)/obj/tables/%.o: tables/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CORE_FLAGS) $(OPT) -MMD -MP -c $< -o $@
$(BUILD)/san/obj/src/%.o: src/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CORE_FLAGS) $(SAN) -MMD -MP -c $< -o $@
$(BUILD)/san/obj/tables/%.o: tables/%.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CORE_FLAGS) $(SAN) -MMD -MP -c $< -o $@

# host code (tools, platform, tests)
$(BUILD)/obj/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(HOST_FLAGS) $(OPT) -MMD -MP -c $< -o $@
$(BUILD)/san/obj/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(HOST_FLAGS) $(SAN) -MMD -MP -c $< -o $@

$(BUILD)/libmaskline.a: $(CORE_OBJ)
	@rm -f $@; ar rcs $@ $^
$(BUILD)/san/libmaskline.a: $(CORE_SOBJ)
	@rm -f $@; ar rcs $@ $^

$(BUILD)/maskline: $(BUILD)/obj/platform/host/main.o $(HOST_OBJ) $(SCENEC_OBJ) $(BUILD)/libmaskline.a
	$(CXX) $(OPT) -o $@ $^ $(HOST_LIBS)
$(BUILD)/san/maskline: $(BUILD)/san/obj/platform/host/main.o $(HOST_SOBJ) $(SCENEC_SOBJ) $(BUILD)/san/libmaskline.a
	$(CXX) $(SAN) -o $@ $^ $(HOST_LIBS)

# benchmark driver (tools/bench): one frame under callgrind, plus the z-buffer baseline
# (bench quality compares with the test oracle, a double-precision reference rasterizer)
ORACLE_SRC := tests/oracle/oracle.cpp tests/oracle/scene_triangles.cpp
$(BUILD)/bench: $(call rel,$(BENCH_SRC)) $(call rel,$(ORACLE_SRC)) $(HOST_OBJ) $(SCENEC_OBJ) $(BUILD)/libmaskline.a
	$(CXX) $(OPT) -o $@ $^ $(HOST_LIBS)

# side_by_side: joins PNG pictures for make demo (tools/picture)
$(BUILD)/side_by_side: $(call rel,tools/picture/side_by_side.cpp) $(BUILD)/obj/platform/host/png_io.o
	$(CXX) $(OPT) -o $@ $^ -lpng

# sort_bench: instructions of the scanline renderer's active-list sorts (docs/scanline.md)
$(BUILD)/sort_bench: $(call rel,tools/bench/sort/sort_bench.cpp)
	$(CXX) $(OPT) -o $@ $^

# maskgen states its tables' CRC-32 with the core's crc32 (the one function of src/ it links).
$(BUILD)/maskgen: $(call rel,$(MASKGEN_SRC) src/core/crc32.cpp)
	$(CXX) $(OPT) -o $@ $^

$(BUILD)/san/tests: $(TEST_SOBJ) $(HOST_SOBJ) $(SCENEC_SOBJ) $(BUILD)/san/libmaskline.a
	@if [ -d $@ ]; then rm -rf $@; fi  # object folder of older builds (objects now live in san/obj/)
	$(CXX) $(SAN) -o $@ $^ -lgtest_main -lgtest -lpthread $(HOST_LIBS)

# ---- the QEMU framebuffer test (tests/qemu-fbdev): a static guest program and the host-side check ----
QEMU_FB_CORE := src/core/arena.cpp src/core/band.cpp src/core/pixel_format.cpp
$(BUILD)/qemu-fbdev/fb_pattern: tests/qemu-fbdev/fb_pattern.cpp tests/qemu-fbdev/pattern.h platform/linux/fbdev/fbdev_sink.cpp platform/linux/fbdev/fbdev_sink.h $(QEMU_FB_CORE)
	@mkdir -p $(dir $@)
	$(CXX) $(HOST_FLAGS) -O2 -static -o $@ tests/qemu-fbdev/fb_pattern.cpp platform/linux/fbdev/fbdev_sink.cpp $(QEMU_FB_CORE)
$(BUILD)/qemu-fbdev/fb_check: $(BUILD)/obj/tests/qemu-fbdev/fb_check.o $(BUILD)/obj/platform/host/png_io.o $(call rel,$(QEMU_FB_CORE))
	@mkdir -p $(dir $@)
	$(CXX) $(OPT) -o $@ $^ $(HOST_LIBS)
# The CLI linked static (libpng, zlib, libgpiod from the Debian -dev packages' .a files): runs in the
# guest (`maskline show --display fb:/dev/fb0`) and renders the host-side reference.
$(BUILD)/qemu-fbdev/maskline: $(BUILD)/obj/platform/host/main.o $(HOST_OBJ) $(SCENEC_OBJ) $(BUILD)/libmaskline.a
	@mkdir -p $(dir $@)
	$(CXX) $(OPT) -static -o $@ $^ $(HOST_LIBS) -lz -lm
QEMU_FB := $(BUILD)/qemu-fbdev/fb_pattern $(BUILD)/qemu-fbdev/fb_check $(BUILD)/qemu-fbdev/maskline

# ---- firmware (platform/cortex-m, docs/firmware.md): Cortex-M ELF files in build/firmware/ ----
# ARM objects live in build/firmware/obj/<cpu>/; the host helper build/firmware/fwtool makes the scene
# blobs and the board configuration headers (tools/board).
FW        := $(BUILD)/firmware
ARM_CXX   := arm-none-eabi-g++
FW_FLAGS  := $(CXXSTD) $(WARN) $(INCLUDES) -O2 -g -fno-exceptions -fno-rtti -fno-use-cxa-atexit \
             -fno-threadsafe-statics -ffunction-sections -fdata-sections
FW_CPU_m3 := -mcpu=cortex-m3 -mthumb
FW_CPU_m0 := -mcpu=cortex-m0plus -mthumb
# The Cortex-M0+ image is built without textures (core/build.h ML_TEXTURES): its scenes have none, and
# texture mapping, sampling and paging would take 17 KB of its 96 KB budget (docs/firmware.md); and
# without the vertex cache (view/vertex_cache.h ML_VERTEX_CACHE), which its 16 KB of RAM leave no room for.
FW_DEFS_m0 := -DML_TEXTURES=0 -DML_VERTEX_CACHE=0
FW_LD     := -nostartfiles --specs=nano.specs -Wl,--gc-sections -Lplatform/cortex-m/common
FW_COMMON := platform/cortex-m/common/startup.cpp platform/cortex-m/common/semihost.cpp
FW_PANELS := platform/panels/panel.cpp platform/panels/panel_sink.cpp
fwo = $(patsubst %.cpp,$(FW)/obj/$(2)/%.o,$(1))
# Scenes in flash: the bundled default on every board (107 KB packed, so it fits the 256 KB boards
# too); FW_SMALL_SCENE replaces it on the 256 KB boards (any `fwtool scene` argument, e.g. office:1 or
# plain:FILE.glb, a model without its texels).
FW_SMALL_SCENE ?= default
# FW_CHECK_CRC=0: the firmware skips the CRC-32 over the whole blob at boot (read_scene's structural
# checks still run).
FW_CHECK_CRC ?= 1
# Texture mapping, sampling and paging are compiled for size on the boards (their scenes have no
# textures; at -O2 src/texture/ is 21 KB of Thumb-1 code, at -Os 10 KB), and the sampler without its
# runs specialized by wrap mode (10 KB more): the same integer results.
fw_opt = $(if $(filter src/texture/%,$(1)),-Os -DML_TEXTURE_RUNS_GENERAL_ONLY)
FW_ELFS := $(FW)/mps2-an385-tiler.elf $(FW)/mps2-an385-scanline.elf $(FW)/mps2-an385-calls.elf $(FW)/lm3s6965evb-tiler.elf $(FW)/lm3s6965evb-scanline.elf $(FW)/m0plus.elf \
           $(FW)/m0plus-boxtextured.elf

$(FW)/obj/m3/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(ARM_CXX) $(FW_FLAGS) $(FW_CPU_m3) $(call fw_opt,$<) -MMD -MP -c $< -o $@
$(FW)/obj/m0/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(ARM_CXX) $(FW_FLAGS) $(FW_CPU_m0) $(FW_DEFS_m0) $(call fw_opt,$<) -MMD -MP -c $< -o $@
$(FW)/obj/m3/libmaskline.a: $(call fwo,$(CORE_SRC),m3)
	@rm -f $@; arm-none-eabi-ar rcs $@ $^
$(FW)/obj/m0/libmaskline.a: $(call fwo,$(CORE_SRC),m0)
	@rm -f $@; arm-none-eabi-ar rcs $@ $^

$(FW)/fwtool: $(call rel,tools/board/fwtool.cpp) $(HOST_OBJ) $(SCENEC_OBJ) $(BUILD)/libmaskline.a
	@mkdir -p $(dir $@)
	$(CXX) $(OPT) -o $@ $^ $(HOST_LIBS)
# Rebuilt with fwtool (whose compiler writes the format).
$(FW)/scenes/default.mls: $(FW)/fwtool
	@mkdir -p $(dir $@)
	$(FW)/fwtool scene default -o $@
$(FW)/scenes/small.mls: $(FW)/fwtool
	@mkdir -p $(dir $@)
	$(FW)/fwtool scene $(FW_SMALL_SCENE) -o $@
# A textured model for the Cortex-M0+ image built without textures (tests/firmware: drawn as the same
# model compiled without its images). Debian's assimp-testmodels (tools/bootstrap.sh).
FW_TEXTURED_GLB := /usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb
$(FW)/scenes/boxtextured.mls: $(FW)/fwtool
	@mkdir -p $(dir $@)
	$(FW)/fwtool scene $(FW_TEXTURED_GLB) -o $@

# One firmware image: board main compiled with a configuration header, the scene blob, startup and
# the core. $(1) elf, $(2) cpu, $(3) main source, $(4) config header, $(5) scene, $(6) memory.ld,
# $(7) extra sources, $(8) extra flags (main compile and link)
define fw_image
$(1): $(3) $(4) $(5) $(6) platform/cortex-m/common/scene_blob.S $(call fwo,$(FW_COMMON) $(7),$(2)) $(FW)/obj/$(2)/libmaskline.a $(wildcard src/*/*.h platform/panels/*.h platform/cortex-m/*/*.h platform/cortex-m/common/*.ld)
	@mkdir -p $$(dir $$@)
	$(ARM_CXX) $(FW_FLAGS) $(FW_CPU_$(2)) $(FW_DEFS_$(2)) $(8) -DFW_CHECK_CRC=$(FW_CHECK_CRC) -include $(4) -c $(3) -o $$(basename $$@)-main.o
	$(ARM_CXX) $(FW_CPU_$(2)) -DFW_SCENE_FILE='"$(5)"' -c platform/cortex-m/common/scene_blob.S -o $$(basename $$@)-scene.o
	$(ARM_CXX) $(FW_CPU_$(2)) $(FW_LD) $(8) -T $(6) -Wl,-Map=$$(basename $$@).map -o $$@ $$(basename $$@)-main.o $$(basename $$@)-scene.o $(call fwo,$(FW_COMMON) $(7),$(2)) $(FW)/obj/$(2)/libmaskline.a
endef
$(FW)/obj/m3/%.o: %.S
	@mkdir -p $(dir $@)
	$(ARM_CXX) $(FW_CPU_m3) -c $< -o $@
# mps2-an385-calls: the mps2 firmware with the core's calls to these runtime helpers counted
FW_COUNTED := __aeabi_ldivmod __aeabi_uldivmod __ctzdi2
fw_comma := ,
FW_WRAP := -DFW_COUNT_CALLS $(foreach f,$(FW_COUNTED),-Wl$(fw_comma)--wrap=$(f))

$(FW)/config/%.h: | $(FW)/fwtool
	@mkdir -p $(dir $@)
	$(FW)/fwtool config $(FW_CONFIG_ARGS_$*) -o $@
FW_CONFIG_ARGS_mps2 := --size 320x240 --format rgb565
FW_CONFIG_ARGS_mps2-tiler := --size 320x240 --format rgb565 --renderer tiler
FW_CONFIG_ARGS_mps2-scanline := --size 320x240 --format rgb565 --renderer scanline
FW_CONFIG_ARGS_lm3s-tiler := --size 128x64 --format grey4 --renderer tiler
FW_CONFIG_ARGS_lm3s-scanline := --size 128x64 --format grey4 --renderer scanline
FW_CONFIG_ARGS_m0plus := --size 128x64 --format grey4 --renderer tiler

# One image a renderer, as a product would ship (each links only its renderer); the -calls image
# renders with both (a diagnostic build: its size is not a product's).
$(eval $(call fw_image,$(FW)/mps2-an385-tiler.elf,m3,platform/cortex-m/mps2-an385/main.cpp,$(FW)/config/mps2-tiler.h,$(FW)/scenes/default.mls,platform/cortex-m/mps2-an385/memory.ld,))
$(eval $(call fw_image,$(FW)/mps2-an385-scanline.elf,m3,platform/cortex-m/mps2-an385/main.cpp,$(FW)/config/mps2-scanline.h,$(FW)/scenes/default.mls,platform/cortex-m/mps2-an385/memory.ld,))
$(eval $(call fw_image,$(FW)/mps2-an385-calls.elf,m3,platform/cortex-m/mps2-an385/main.cpp,$(FW)/config/mps2.h,$(FW)/scenes/default.mls,platform/cortex-m/mps2-an385/memory.ld,$(FW)/obj/m3/platform/cortex-m/common/call_shims.o platform/cortex-m/common/call_count.cpp,$(FW_WRAP)))
$(eval $(call fw_image,$(FW)/lm3s6965evb-tiler.elf,m3,platform/cortex-m/lm3s6965evb/main.cpp,$(FW)/config/lm3s-tiler.h,$(FW)/scenes/small.mls,platform/cortex-m/lm3s6965evb/memory.ld,$(FW_PANELS) platform/cortex-m/lm3s6965evb/ssi_transport.cpp))
$(eval $(call fw_image,$(FW)/lm3s6965evb-scanline.elf,m3,platform/cortex-m/lm3s6965evb/main.cpp,$(FW)/config/lm3s-scanline.h,$(FW)/scenes/small.mls,platform/cortex-m/lm3s6965evb/memory.ld,$(FW_PANELS) platform/cortex-m/lm3s6965evb/ssi_transport.cpp))
$(eval $(call fw_image,$(FW)/m0plus.elf,m0,platform/cortex-m/m0plus/main.cpp,$(FW)/config/m0plus.h,$(FW)/scenes/small.mls,platform/cortex-m/m0plus/memory.ld,,-Os))
$(eval $(call fw_image,$(FW)/m0plus-boxtextured.elf,m0,platform/cortex-m/m0plus/main.cpp,$(FW)/config/m0plus.h,$(FW)/scenes/boxtextured.mls,platform/cortex-m/m0plus/memory.ld,,-Os))

# tools/board/render-on-qemu: a scene and options of its own in build/firmware/custom/NAME/
$(FW)/custom/%/mps2-an385.elf: $(FW)/custom/%/config.h $(FW)/custom/%/scene.mls $(call fwo,$(FW_COMMON),m3) $(FW)/obj/m3/libmaskline.a platform/cortex-m/mps2-an385/main.cpp $(wildcard src/*/*.h platform/cortex-m/*/*.h)
	$(ARM_CXX) $(FW_FLAGS) $(FW_CPU_m3) -include $(FW)/custom/$*/config.h -c platform/cortex-m/mps2-an385/main.cpp -o $(basename $@)-main.o
	$(ARM_CXX) $(FW_CPU_m3) -DFW_SCENE_FILE='"$(FW)/custom/$*/scene.mls"' -c platform/cortex-m/common/scene_blob.S -o $(basename $@)-scene.o
	$(ARM_CXX) $(FW_CPU_m3) $(FW_LD) -T platform/cortex-m/mps2-an385/memory.ld -o $@ $(basename $@)-main.o $(basename $@)-scene.o $(call fwo,$(FW_COMMON),m3) $(FW)/obj/m3/libmaskline.a

.PHONY: firmware
firmware: bootstrap
	@$(MAKE) --no-print-directory $(FW_ELFS) $(BUILD)/maskline

# ---- fuzzing: clang libFuzzer over the blob reader and, on what it accepts, both renderers ----
FUZZ_SRC := tests/fuzz/fuzz_blob_reader.cpp $(CORE_SRC)
$(BUILD)/fuzz_blob_reader: $(FUZZ_SRC) $(shell find src tables -name '*.h') tests/fuzz/checked_render.h
	@mkdir -p $(BUILD)
	$(CLANGXX) $(CXXSTD) $(INCLUDES) -O1 -g -fno-exceptions -fsanitize=fuzzer,address,undefined -o $@ $(FUZZ_SRC)

# ---- fuzzing: clang libFuzzer over the glTF importer, compiler and both renderers ----
# Objects in build/fuzz/obj/ (instrumented for coverage), linked with libFuzzer's main.
FUZZ_GLTF_OBJ := $(patsubst %.cpp,$(BUILD)/fuzz/obj/%.o,tests/fuzz/fuzz_gltf_import.cpp $(CORE_SRC) $(SCENEC_SRC))
$(BUILD)/fuzz/obj/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CLANGXX) $(CXXSTD) $(INCLUDES) -O1 -g -fsanitize=fuzzer-no-link,address,undefined -MMD -MP -c $< -o $@
$(BUILD)/fuzz_gltf_import: $(FUZZ_GLTF_OBJ)
	$(CLANGXX) -O1 -g -fsanitize=fuzzer,address,undefined -o $@ $^

fuzz: bootstrap
	@$(MAKE) --no-print-directory $(BUILD)/fuzz_blob_reader $(BUILD)/fuzz_gltf_import $(BUILD)/maskline
	bash tests/fuzz/run.sh $(BUILD) 60
	bash tests/fuzz/run_gltf.sh $(BUILD) 60

test: bootstrap
	@$(MAKE) --no-print-directory $(BUILD)/san/tests $(BUILD)/san/maskline $(BUILD)/maskline $(BUILD)/maskgen $(BUILD)/fuzz_blob_reader \
	  $(BUILD)/fuzz_gltf_import $(QEMU_FB) $(FW_ELFS)
	@bash tests/run_all.sh $(BUILD) $(MASK_K)

tables: $(BUILD)/maskgen
	$(BUILD)/maskgen --k $(MASK_K) --out tables

demo: all
	@$(MAKE) --no-print-directory $(BUILD)/side_by_side
	@bash tools/demo.sh $(BUILD)

bench: all
	@$(MAKE) --no-print-directory $(BUILD)/bench $(BUILD)/sort_bench
	@bash tools/bench/run.sh $(BUILD)

# the firmware images under QEMU: instructions a frame, flash and RAM (docs/benchmarks.md, Boards)
bench-board: firmware
	@$(MAKE) --no-print-directory $(BUILD)/bench
	+@bash tools/bench/board.sh $(BUILD)

clean:
	rm -rf $(BUILD) out

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
