# maskline: the one build entry. See README.md.
#   make          host build into build/ (library, CLI, tools)
#   make test     every test, sanitized; last line "N passed, N failed"
#   make demo     render the bundled scene (and 2CylinderEngine when installed) into out/
#   make tables   regenerate tables/ from tools/maskgen
#   make fuzz     run the blob-reader fuzzer for a minute
#   make bench    instruction counts (callgrind) for both renderers against a z-buffer baseline

BUILD   ?= build
CXX     ?= g++
CLANGXX ?= clang++
# Mask-table interval count per side (tables/ holds the generated arrays for this k).
MASK_K  ?= 16

WARN      := -Wall -Wextra -Werror
CXXSTD    := -std=c++17
INCLUDES  := -Isrc -I.
# src/ runs on the board: integer-only (a float is a compile error), no exceptions, no RTTI.
CORE_FLAGS := $(CXXSTD) $(WARN) $(INCLUDES) -mgeneral-regs-only -fno-exceptions -fno-rtti
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

.PHONY: all test demo tables fuzz bench clean bootstrap
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
$(BUILD)/bench: $(call rel,$(BENCH_SRC)) $(HOST_OBJ) $(SCENEC_OBJ) $(BUILD)/libmaskline.a
	$(CXX) $(OPT) -o $@ $^ $(HOST_LIBS)

# sort_bench: instructions of the scanline renderer's active-list sorts (docs/scanline.md)
$(BUILD)/sort_bench: $(call rel,tools/bench/sort/sort_bench.cpp)
	$(CXX) $(OPT) -o $@ $^

$(BUILD)/maskgen: $(call rel,$(MASKGEN_SRC))
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
QEMU_FB := $(BUILD)/qemu-fbdev/fb_pattern $(BUILD)/qemu-fbdev/fb_check

# ---- fuzzing: clang libFuzzer over the blob reader ----
FUZZ_SRC := tests/fuzz/fuzz_blob_reader.cpp $(CORE_SRC)
$(BUILD)/fuzz_blob_reader: $(FUZZ_SRC) $(shell find src tables -name '*.h')
	@mkdir -p $(BUILD)
	$(CLANGXX) $(CXXSTD) $(INCLUDES) -O1 -g -fno-exceptions -fsanitize=fuzzer,address,undefined -o $@ $(FUZZ_SRC)

fuzz: bootstrap
	@$(MAKE) --no-print-directory $(BUILD)/fuzz_blob_reader $(BUILD)/maskline
	bash tests/fuzz/run.sh $(BUILD) 60

test: bootstrap
	@$(MAKE) --no-print-directory $(BUILD)/san/tests $(BUILD)/san/maskline $(BUILD)/maskgen $(BUILD)/fuzz_blob_reader $(QEMU_FB)
	@bash tests/run_all.sh $(BUILD) $(MASK_K)

tables: $(BUILD)/maskgen
	$(BUILD)/maskgen --k $(MASK_K) --out tables

demo: all
	@bash tools/demo.sh $(BUILD)

bench: all
	@$(MAKE) --no-print-directory $(BUILD)/bench $(BUILD)/sort_bench
	@bash tools/bench/run.sh $(BUILD)

clean:
	rm -rf $(BUILD) out

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
