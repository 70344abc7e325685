# maskline: the one build entry. See README.md.
#   make          host build into build/ (library, CLI, tools)
#   make test     every test, sanitized; last line "N passed, N failed"
#   make demo     render the bundled scene (and 2CylinderEngine when installed) into out/
#   make tables   regenerate tables/ from tools/maskgen
#   make fuzz     run the blob-reader and glTF-import fuzzers for a minute each
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
HOST_SRC  := $(filter-out platform/host/main.cpp,$(shell find platform/host -name '*.cpp' 2>/dev/null | sort))
TEST_SRC  := $(shell find tests -name '*.cpp' -not -path 'tests/fuzz/*' 2>/dev/null | sort)
MASKGEN_SRC := $(shell find tools/maskgen -name '*.cpp' 2>/dev/null | sort)
BENCH_SRC := $(shell find tools/bench -name '*.cpp' 2>/dev/null | sort)

HOST_LIBS := -lpng

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

$(BUILD)/maskgen: $(call rel,$(MASKGEN_SRC))
	$(CXX) $(OPT) -o $@ $^

$(BUILD)/san/tests: $(TEST_SOBJ) $(HOST_SOBJ) $(SCENEC_SOBJ) $(BUILD)/san/libmaskline.a
	@if [ -d $@ ]; then rm -rf $@; fi  # object folder of older builds (objects now live in san/obj/)
	$(CXX) $(SAN) -o $@ $^ -lgtest_main -lgtest -lpthread $(HOST_LIBS)

# ---- fuzzing: clang libFuzzer over the blob reader ----
FUZZ_SRC := tests/fuzz/fuzz_blob_reader.cpp $(CORE_SRC)
$(BUILD)/fuzz_blob_reader: $(FUZZ_SRC) $(shell find src tables -name '*.h')
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
	@$(MAKE) --no-print-directory $(BUILD)/san/tests $(BUILD)/san/maskline $(BUILD)/maskgen $(BUILD)/fuzz_blob_reader \
	  $(BUILD)/fuzz_gltf_import
	@bash tests/run_all.sh $(BUILD) $(MASK_K)

tables: $(BUILD)/maskgen
	$(BUILD)/maskgen --k $(MASK_K) --out tables

demo: all
	@bash tools/demo.sh $(BUILD)

bench: all
	@$(MAKE) --no-print-directory $(BUILD)/bench
	@bash tools/bench/run.sh $(BUILD)

clean:
	rm -rf $(BUILD) out

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
