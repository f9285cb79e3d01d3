# egofuse - build, test, demo.
#
#   make            library, io library, the egofuse program, tests, tools
#   make demo       install what the demo is missing, generate samples, run it
#   make test       install what the tests are missing, build, run every test
#   make debug      the same tests under ASan + UBSan (build-debug/);
#                   EGOFUSE_VM=0 make debug skips the VM test
#   make fuzz       libFuzzer + ASan + UBSan targets of every parser, clang
#                   (build-fuzz/fuzz/; scripts/fuzz.sh runs them, docs/fuzzing.md)
#   make bench      install the peers, benchmarks (they report, never pass or fail)
#   make deps       install what demo, test and bench need (scripts/deps.sh)
#   make soak       `egofuse run` for 10 minutes in the test VM, cameras
#                   unplugged 20 times, V stalled; RSS and fds sampled
#                   (tests/vm/soak_host.sh, docs/devices.md; not in make test)
#   make install    PREFIX=/usr/local DESTDIR=: the libraries, headers, pkg-config
#                   files, plugin and program (docs/library.md); make uninstall
#   make core-tests the core library and its tests only (no io library):
#                   the ARM64 cross build of CI, .ci/run and docs/portability.md
#   make clean
#
# Parallel by default: as many jobs as cores (nproc), unless the command
# line or the environment gives -j (make -j1 builds one thing at a time).
#
# Core (src/raster, src/kin, src/fuse, src/fit, src/pipe, src/cpu): libc + libm + pthreads only, built
# into build/libegofuse.a. src/io holds every other dependency and builds
# into build/libegofuse_io.a. C++ only in src/io/*.cpp.

# Parallel by default: -j$(nproc) when neither the command line nor the
# environment's MAKEFLAGS gives -j. Only in the top make: a recursive make
# ($(MAKE) below) shares its parent's job slots. GNU make 4.3 shows a
# command-line -j in MAKEFLAGS only after reading the makefile, but its
# command line overrides the value set here; make 4.4 shows it at once.
ifeq ($(MAKELEVEL),0)
ifeq ($(findstring j,$(filter-out --%,$(MAKEFLAGS) $(shell printf '%s' "$$MAKEFLAGS"))),)
MAKEFLAGS += -j$(shell nproc 2>/dev/null || echo 1)
endif
# Goals that install packages and run a make of their own: one after the
# other (make demo test), each building in parallel underneath.
ifneq ($(filter deps deps-% demo test debug bench eval samples fuzz,$(MAKECMDGOALS)),)
.NOTPARALLEL:
endif
endif

BUILD    ?= build
CC       ?= cc
CXX      ?= c++
OPT      ?= -O2
SAN      ?=
# Deterministic float: no contraction into FMA, no fast-math (docs/rounding.md).
CFLAGS_COMMON = $(OPT) -g -Wall -Wextra -ffp-contract=off -fno-fast-math \
                -fno-strict-aliasing -D_GNU_SOURCE -MMD -MP $(SAN)
CFLAGS   += -std=c11 $(CFLAGS_COMMON)
CXXFLAGS += -std=c++17 $(CFLAGS_COMMON)
LDFLAGS  += $(SAN)

# The target machine of $(CC) (x86_64-linux-gnu, aarch64-linux-gnu, ...):
# the x86 ISA files get their -m flags only there (elsewhere they compile
# to nothing and the dispatch keeps the portable path, src/cpu/cpu.c).
TARGET   := $(shell $(CC) -dumpmachine 2>/dev/null)
X86      := $(if $(filter x86_64-% i386-% i486-% i586-% i686-%,$(TARGET)),1,)
# cmocka: the system's, or another one (CI's ARM64 cross build passes
# the arm64 package unpacked into a folder, .ci/run).
CMOCKA_CFLAGS ?=
CMOCKA_LIBS   ?= -lcmocka

CORE_SRC := $(wildcard src/cpu/*.c src/pipe/*.c src/fit/*.c src/raster/*.c src/kin/*.c src/fuse/*.c)
IO_SRC   := $(wildcard src/io/*.c)
# io_image_oiio.cpp and io_image_exr.cpp are the image plugin, not part of
# the io library.
IO_CXX   := $(filter-out src/io/io_image_oiio.cpp src/io/io_image_exr.cpp,$(wildcard src/io/*.cpp))
CLI_SRC  := $(wildcard src/cli/*.c)
# The evaluation (`egofuse eval`): linked into the program with the samples
# library it needs, never into the core or io libraries.
EVAL_SRC := $(wildcard src/eval/*.c)
GEN_SRC  := $(wildcard samples/gen/*.c)
GT_SRC   := $(wildcard samples/gt/*.c)
TEST_SRC := $(wildcard tests/test_*.c)
# Tests of the io library, the samples, the program or the VM: not part of
# core-tests. scripts/io_tests.pl reads the code without its comments.
IO_TEST_SRC := $(shell perl scripts/io_tests.pl $(TEST_SRC)) tests/test_vm.c
CORE_TEST_SRC := $(filter-out $(IO_TEST_SRC),$(TEST_SRC))
TEST_SHARED := $(wildcard tests/support/*.c)
BENCH_SRC := $(wildcard bench/bench_*.c)
LLVMPIPE_SRC := $(wildcard bench/llvmpipe/*.c)

obj = $(patsubst %,$(BUILD)/obj/%.o,$(1))
CORE_OBJ := $(call obj,$(CORE_SRC))
IO_OBJ   := $(call obj,$(IO_SRC) $(IO_CXX))
CLI_OBJ  := $(call obj,$(CLI_SRC) $(EVAL_SRC))
GEN_OBJ  := $(call obj,$(GEN_SRC))
# The generator's scenes and the ground truth of `egofuse eval`, shared by
# build/gen_samples and build/egofuse.
SAMPLES_LIB_OBJ := $(filter-out %/gen_main.c.o,$(GEN_OBJ)) $(call obj,$(GT_SRC))
TEST_SHARED_OBJ := $(call obj,$(TEST_SHARED))
TEST_BIN := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))
CORE_TEST_BIN := $(patsubst tests/%.c,$(BUILD)/tests/%,$(CORE_TEST_SRC))
BENCH_BIN := $(patsubst bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC)) \
             $(patsubst bench/llvmpipe/%.c,$(BUILD)/bench/%,$(LLVMPIPE_SRC))

IO_PKGS  := libpng tinygltf libusb-1.0 libv4l2 libdrm
ifeq ($(CORE_ONLY),1)
# core-tests: the tests link the core library alone.
IO_CFLAGS :=
IO_LIBS  :=
TEST_IOLIB :=
TEST_PLUGIN :=
else
# SDL2: headers only; src/io/io_display_sdl.c loads libSDL2 with dlopen when
# a window is opened, so the program does not link it.
IO_CFLAGS := $(shell pkg-config --cflags $(IO_PKGS) 2>/dev/null)
# SDL2's headers (make test installs them, make demo does not): without
# them io_display_sdl.c builds as a stub that says so.
SDL2_CFLAGS := $(shell pkg-config --cflags sdl2 2>/dev/null || echo -DEGOFUSE_NO_SDL2)
IO_LIBS  := $(shell pkg-config --libs $(IO_PKGS) 2>/dev/null) -lmeshoptimizer -lstdc++ -ldl
TEST_IOLIB = $(IOLIB)
TEST_PLUGIN = $(OIIO_PLUGIN)
endif
# OpenImageIO (EXR, TIFF, JPEG ...) lives in a plugin that io_image.c loads
# with dlopen only when a file is neither PNG nor PPM/PGM (docs/io.md), so
# no command pays for its ~260 libraries unless it reads or writes such a
# file. It is found next to the program (or its parent folder).
# Where OpenImageIO is missing but OpenEXR is there (make demo installs
# only OpenEXR: the samples' depth is EXR), the plugin is built from
# io_image_exr.cpp and serves EXR alone; it is rebuilt with OpenImageIO
# once that is installed (make test). With OpenEXR, build/exr/ also holds
# that EXR-only plugin, which tests/test_io_exr_plugin.c compares with
# OpenImageIO's.
HAVE_OIIO := $(shell pkg-config --exists OpenImageIO 2>/dev/null && echo 1)
HAVE_EXR := $(shell pkg-config --exists OpenEXR 2>/dev/null && echo 1)
PLUGIN_KIND := $(if $(HAVE_OIIO),oiio,$(if $(HAVE_EXR),exr,oiio))
OIIO_PKGS := $(if $(filter exr,$(PLUGIN_KIND)),OpenEXR,OpenImageIO)
OIIO_CFLAGS := $(shell pkg-config --cflags $(OIIO_PKGS) 2>/dev/null)
OIIO_LIBS := $(shell pkg-config --libs $(OIIO_PKGS) 2>/dev/null)
OIIO_PLUGIN := $(BUILD)/libegofuse_oiio.so
OIIO_PLUGIN_SRC := src/io/io_image_$(PLUGIN_KIND).cpp src/io/io_common.c src/io/io_image_mem.c
OIIO_PLUGIN_OBJ := $(patsubst %,$(BUILD)/pic/%.o,$(OIIO_PLUGIN_SRC))
EXR_CFLAGS := $(shell pkg-config --cflags OpenEXR 2>/dev/null)
EXR_LIBS := $(shell pkg-config --libs OpenEXR 2>/dev/null)
EXR_PLUGIN := $(if $(HAVE_EXR),$(BUILD)/exr/libegofuse_oiio.so)
EXR_PLUGIN_OBJ := $(patsubst %,$(BUILD)/pic/%.o,src/io/io_image_exr.cpp src/io/io_common.c src/io/io_image_mem.c)
SYS_LIBS := -lm -lpthread
# Peers measured by the benchmarks: pixman (compositing), Mesa llvmpipe
# through EGL + GLES (the same frame as GL shaders).
BENCH_CFLAGS := $(shell pkg-config --cflags pixman-1 egl glesv2 2>/dev/null)
BENCH_LIBS := $(shell pkg-config --libs pixman-1 2>/dev/null)
GL_LIBS  := $(shell pkg-config --libs egl glesv2 2>/dev/null)

LIB      := $(BUILD)/libegofuse.a
IOLIB    := $(BUILD)/libegofuse_io.a
SAMPLESLIB := $(BUILD)/libegofuse_samples.a
EGOFUSE  := $(BUILD)/egofuse
GEN      := $(BUILD)/gen_samples
SAMPLES  := $(BUILD)/samples

.PHONY: all test-bins deps deps-demo deps-test deps-bench demo test debug bench clean samples check-headers eval core-tests fuzz fuzz-targets soak
.DEFAULT_GOAL := all
# Keep intermediate objects (tests/support/*.o), so a second make rebuilds nothing.
.SECONDARY:

all: test-bins $(BENCH_BIN)
# Everything make test (and make debug) runs: all but the benchmarks.
test-bins: $(LIB) $(IOLIB) $(OIIO_PLUGIN) $(EXR_PLUGIN) $(EGOFUSE) $(GEN) $(TEST_BIN)

# Each command installs only what it needs (scripts/deps.sh).
deps:
	@sh scripts/deps.sh
deps-demo:
	@sh scripts/deps.sh demo
deps-test:
	@sh scripts/deps.sh test
deps-bench:
	@sh scripts/deps.sh bench

# Per-ISA files get their own flags; everything else stays at the baseline.
# *_neon.c (the vector layer's src/cpu/simd_neon.h) need none: Advanced SIMD
# is the aarch64 baseline; elsewhere they compile to nothing, as the x86
# files do off x86.
ifeq ($(X86),1)
$(BUILD)/obj/%_avx2.c.o: CFLAGS += -mavx2 -mf16c
$(BUILD)/obj/%_avx512.c.o: CFLAGS += -mavx512f -mavx512bw -mavx512dq -mavx512vl -mavx2 -mf16c
$(BUILD)/obj/%_sse41.c.o: CFLAGS += -msse4.1
endif

# The core library and the tests that need nothing else (CORE_ONLY=1 so
# that they link without the io library): CI's ARM64 cross build,
#   make CORE_ONLY=1 CC=aarch64-linux-gnu-gcc BUILD=build-arm64 core-tests
core-tests: $(LIB) $(CORE_TEST_BIN)

$(BUILD)/obj/src/io/%.o: CFLAGS += $(IO_CFLAGS)
$(BUILD)/obj/src/io/%.o: CXXFLAGS += $(IO_CFLAGS) -Wno-unused-parameter
# Rebuilt when SDL2's headers come or go (make demo, then make test).
$(BUILD)/obj/src/io/io_display_sdl.c.o: CFLAGS += $(SDL2_CFLAGS)
$(BUILD)/obj/src/io/io_display_sdl.c.o: $(BUILD)/cfg/sdl2
$(BUILD)/tests/test_io_display: CFLAGS += $(SDL2_CFLAGS)
$(BUILD)/cfg/sdl2: FORCE
	@mkdir -p $(dir $@)
	@echo '$(SDL2_CFLAGS)' | cmp -s - $@ || echo '$(SDL2_CFLAGS)' > $@

$(BUILD)/obj/%.c.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/%.cpp.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -c $< -o $@

$(BUILD)/pic/%.c.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fPIC -fvisibility=hidden -c $< -o $@

$(BUILD)/pic/%.cpp.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(OIIO_CFLAGS) -Wno-unused-parameter -fPIC -fvisibility=hidden -c $< -o $@

$(BUILD)/pic/src/io/io_image_exr.cpp.o: OIIO_CFLAGS := $(EXR_CFLAGS)

# Rebuilt when the library behind it changes (OpenEXR, then OpenImageIO).
$(OIIO_PLUGIN): $(OIIO_PLUGIN_OBJ) $(BUILD)/cfg/plugin
	$(CXX) -shared $(LDFLAGS) -Wl,-soname,libegofuse_oiio.so -o $@ $(OIIO_PLUGIN_OBJ) $(OIIO_LIBS) -lm
$(BUILD)/cfg/plugin: FORCE
	@mkdir -p $(dir $@)
	@echo '$(PLUGIN_KIND)' | cmp -s - $@ || echo '$(PLUGIN_KIND)' > $@

$(BUILD)/exr/libegofuse_oiio.so: $(EXR_PLUGIN_OBJ)
	@mkdir -p $(dir $@)
	$(CXX) -shared $(LDFLAGS) -Wl,-soname,libegofuse_oiio.so -o $@ $^ $(EXR_LIBS) -lm

$(LIB): $(CORE_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(IOLIB): $(IO_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(SAMPLESLIB): $(SAMPLES_LIB_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(EGOFUSE): $(CLI_OBJ) $(SAMPLESLIB) $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	$(CXX) $(LDFLAGS) -o $@ $(CLI_OBJ) $(SAMPLESLIB) $(IOLIB) $(LIB) $(IO_LIBS) $(SYS_LIBS)

$(GEN): $(BUILD)/obj/samples/gen/gen_main.c.o $(SAMPLESLIB) $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	$(CXX) $(LDFLAGS) -o $@ $< $(SAMPLESLIB) $(IOLIB) $(LIB) $(IO_LIBS) $(SYS_LIBS)

$(BUILD)/tests/%: tests/%.c $(TEST_SHARED_OBJ) $(TEST_IOLIB) $(LIB) | $(TEST_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) $(CMOCKA_CFLAGS) -o $@ $< $(TEST_SHARED_OBJ) $(TEST_IOLIB) $(LIB) \
	    $(CMOCKA_LIBS) $(IO_LIBS) $(SYS_LIBS) $(LDFLAGS)

# Tests on the generated samples' scenes also link the generator.
$(BUILD)/tests/test_occlusion $(BUILD)/tests/test_io_lod $(BUILD)/tests/test_eval_eye: $(BUILD)/tests/%: tests/%.c $(TEST_SHARED_OBJ) $(SAMPLESLIB) $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) -o $@ $< $(TEST_SHARED_OBJ) $(SAMPLESLIB) $(IOLIB) $(LIB) \
	    -lcmocka $(IO_LIBS) $(SYS_LIBS) $(LDFLAGS)

# The AA study runs on the generated operator: it links the samples library.
$(BUILD)/bench/bench_aa: bench/bench_aa.c $(SAMPLESLIB) $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) -o $@ $< $(SAMPLESLIB) $(IOLIB) $(LIB) \
	    $(IO_LIBS) $(SYS_LIBS) $(LDFLAGS)

$(BUILD)/bench/%: bench/%.c $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) $(BENCH_CFLAGS) -o $@ $< $(IOLIB) $(LIB) \
	    $(BENCH_LIBS) $(IO_LIBS) $(SYS_LIBS) $(LDFLAGS)

$(BUILD)/bench/%: bench/llvmpipe/%.c $(IOLIB) $(LIB) | $(OIIO_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) $(BENCH_CFLAGS) -o $@ $< $(IOLIB) $(LIB) \
	    $(GL_LIBS) $(IO_LIBS) $(SYS_LIBS) $(LDFLAGS)

# Sample data: generated, never downloaded (samples/README.md).
$(SAMPLES)/scene.txt: $(GEN)
	$(GEN) --out $(SAMPLES)

samples: deps-demo
	@$(MAKE) --no-print-directory $(SAMPLES)/scene.txt

demo: deps-demo
	@$(MAKE) --no-print-directory $(EGOFUSE) $(SAMPLES)/scene.txt
	$(EGOFUSE) demo --samples $(SAMPLES) --out out/demo

# make test builds everything but the benchmarks (make bench: their peers).
test: deps-test
	@$(MAKE) --no-print-directory test-bins check-headers
	@sh tests/run_tests.sh $(BUILD)

# Every public header compiles on its own as C and as C++ (sokol's rule).
HEADERS := src/cpu/cpu.h src/cpu/ef_n10.h src/pipe/pipe.h src/pipe/pipe_pose.h src/pipe/pipe_lod.h src/fit/fit.h src/raster/raster.h src/kin/kin.h src/fuse/fuse.h \
           src/fuse/fuse_metrics.h src/fuse/fuse_refine.h src/fuse/fuse_edge.h src/io/io.h src/io/io_dev.h \
           src/io/io_natnet.h src/io/io_display.h src/io/io_sched.h src/io/io_live.h \
           src/io/io_vsrc.h src/io/io_lod.h src/io/io_term.h src/kin/kin_lens.h src/pipe/pipe_lens.h src/io/io_calib.h \
           src/pipe/pipe_reproj.h
check-headers:
	@for h in $(HEADERS); do \
	    echo "#include \"$$h\"" | $(CC) -std=c99 -Wall -Wextra -Werror -x c -fsyntax-only - || exit 1; \
	    echo "#include \"$$h\"" | $(CXX) -Wall -Wextra -Werror -x c++ -fsyntax-only - || exit 1; \
	done

# Tests under AddressSanitizer and UndefinedBehaviorSanitizer.
debug: deps-test
	@$(MAKE) --no-print-directory BUILD=build-debug OPT=-O1 \
	    SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined" test-bins
	@ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp \
	    sh tests/run_tests.sh build-debug

# libFuzzer targets tests/fuzz_*.c, one per parser (docs/fuzzing.md): clang,
# ASan + UBSan (a UB report aborts, so the fuzzer sees it), the libraries
# instrumented for coverage, everything in build-fuzz/. Linked by clang++
# (the sanitizers' C++ runtime, the io library's C++).
FUZZ_SRC := $(wildcard tests/fuzz_*.c)
FUZZ_BIN := $(patsubst tests/%.c,$(BUILD)/fuzz/%,$(FUZZ_SRC))
FUZZ_SAN := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
fuzz:
	@$(MAKE) --no-print-directory BUILD=build-fuzz CC=clang CXX=clang++ OPT=-O1 \
	    SAN="$(FUZZ_SAN) -fsanitize=fuzzer-no-link" fuzz-targets

fuzz-targets: $(FUZZ_BIN)

$(BUILD)/fuzz/%: tests/%.c tests/fuzz/fuzz_util.h $(IOLIB) $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(IO_CFLAGS) -Itests -c $< -o $@.o
	$(CXX) $(LDFLAGS) -fsanitize=fuzzer -o $@ $@.o $(IOLIB) $(LIB) $(IO_LIBS) $(SYS_LIBS)

# The accuracy report (docs/accuracy.md): charts, table, summary.csv; then
# the eye's viewpoint (eval --eyeview: eyeview.csv, eyeview.md, eyeview_*.png).
eval: deps-demo
	@$(MAKE) --no-print-directory $(EGOFUSE)
	$(EGOFUSE) eval --frames 180 --report out/eval
	$(EGOFUSE) eval --eyeview --frames 60 --report out/eval

# The soak of the live path in the VM (SOAK_SECONDS, SOAK_CYCLES, SOAK_STALLS).
soak: deps-test
	@$(MAKE) --no-print-directory $(LIB) $(IOLIB) $(OIIO_PLUGIN) $(EGOFUSE) $(GEN)
	@sh tests/vm/soak_host.sh $(BUILD)

bench: deps-bench
	@$(MAKE) --no-print-directory $(BENCH_BIN) $(GEN) $(OIIO_PLUGIN)
	@sh bench/run_bench.sh $(BUILD)

clean:
	rm -rf build build-debug build-clang build-arm64 build-fuzz out

# ------------------------------------------------------------ install
# make install [PREFIX=/usr/local] [DESTDIR=]  (docs/library.md):
#   lib/libegofuse.a, lib/libegofuse.so.$(SOVERSION) (soname libegofuse.so.0),
#   lib/libegofuse_io.a, lib/egofuse/libegofuse_oiio.so (the OpenImageIO
#   plugin, where the installed io library looks for it), bin/egofuse,
#   include/egofuse/*.h (flattened: "../kin/kin.h" becomes "kin.h"),
#   lib/pkgconfig/egofuse.pc and egofuse-io.pc.
# The shared core is a second, position-independent object tree (build/so);
# the installed io library and program differ from build/'s only by
# io_image.c compiled with EGOFUSE_PLUGIN_DIR (build/inst).
PREFIX    ?= /usr/local
DESTDIR   ?=
LIBDIR    ?= $(PREFIX)/lib
INCDIR    ?= $(PREFIX)/include
BINDIR    ?= $(PREFIX)/bin
PLUGINDIR := $(LIBDIR)/egofuse
SOVERSION := 0.1.0
SOMAJOR   := 0
SOLIB     := $(BUILD)/libegofuse.so.$(SOVERSION)
SO_OBJ    := $(patsubst %,$(BUILD)/so/%.o,$(CORE_SRC))
INST_IOLIB := $(BUILD)/inst/libegofuse_io.a
INST_EGOFUSE := $(BUILD)/inst/egofuse
INST_IO_OBJ := $(filter-out %/io_image.c.o,$(IO_OBJ)) $(BUILD)/inst/io_image.c.o
INSTALL_HEADERS := $(filter-out src/io/%,$(HEADERS)) src/fuse/fuse_normals.h src/pipe/pipe_mask.h \
                   $(filter src/io/%,$(HEADERS))

.PHONY: install uninstall FORCE
ifneq ($(CORE_ONLY),1)
test-bins: $(SOLIB) $(INST_IOLIB) $(INST_EGOFUSE)
endif

ifeq ($(X86),1)
$(BUILD)/so/%_avx2.c.o: CFLAGS += -mavx2 -mf16c
$(BUILD)/so/%_avx512.c.o: CFLAGS += -mavx512f -mavx512bw -mavx512dq -mavx512vl -mavx2 -mf16c
$(BUILD)/so/%_sse41.c.o: CFLAGS += -msse4.1
endif

$(BUILD)/so/%.c.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -fPIC -c $< -o $@

$(SOLIB): $(SO_OBJ)
	$(CC) -shared $(LDFLAGS) -Wl,-soname,libegofuse.so.$(SOMAJOR) -o $@ $^ $(SYS_LIBS)

# The plugin folder compiled into the installed io library: rebuilt when
# PREFIX changes.
$(BUILD)/inst/plugin_dir: FORCE
	@mkdir -p $(dir $@)
	@echo '$(PLUGINDIR)' | cmp -s - $@ || echo '$(PLUGINDIR)' > $@
FORCE:

$(BUILD)/inst/io_image.c.o: src/io/io_image.c $(BUILD)/inst/plugin_dir
	$(CC) $(CFLAGS) $(IO_CFLAGS) -DEGOFUSE_PLUGIN_DIR='"$(PLUGINDIR)"' -c $< -o $@

$(INST_IOLIB): $(INST_IO_OBJ)
	rm -f $@ && ar rcs $@ $^

$(INST_EGOFUSE): $(CLI_OBJ) $(SAMPLESLIB) $(INST_IOLIB) $(LIB)
	$(CXX) $(LDFLAGS) -o $@ $(CLI_OBJ) $(SAMPLESLIB) $(INST_IOLIB) $(LIB) $(IO_LIBS) $(SYS_LIBS)

install: $(LIB) $(SOLIB) $(INST_IOLIB) $(INST_EGOFUSE) $(OIIO_PLUGIN)
	install -d $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(PLUGINDIR) $(DESTDIR)$(INCDIR)/egofuse $(DESTDIR)$(BINDIR)
	install -m 644 $(LIB) $(INST_IOLIB) $(DESTDIR)$(LIBDIR)/
	install -m 755 $(SOLIB) $(DESTDIR)$(LIBDIR)/
	ln -sf libegofuse.so.$(SOVERSION) $(DESTDIR)$(LIBDIR)/libegofuse.so.$(SOMAJOR)
	ln -sf libegofuse.so.$(SOMAJOR) $(DESTDIR)$(LIBDIR)/libegofuse.so
	install -m 755 $(OIIO_PLUGIN) $(DESTDIR)$(PLUGINDIR)/
	install -m 755 $(INST_EGOFUSE) $(DESTDIR)$(BINDIR)/
	@for h in $(INSTALL_HEADERS); do \
	    sed 's|^#include "\.\./[a-z]*/|#include "|' $$h > $(DESTDIR)$(INCDIR)/egofuse/$$(basename $$h) || exit 1; \
	done
	@printf '%s\n' 'prefix=$(PREFIX)' 'libdir=$(LIBDIR)' 'includedir=$(INCDIR)' '' \
	    'Name: egofuse' 'Description: egofuse core: rasterizer, kinematics, compositor, pipeline (libc, libm, pthreads)' \
	    'Version: $(SOVERSION)' 'Cflags: -I$${includedir}' 'Libs: -L$${libdir} -legofuse -lm -lpthread' \
	    > $(DESTDIR)$(LIBDIR)/pkgconfig/egofuse.pc
	@printf '%s\n' 'prefix=$(PREFIX)' 'libdir=$(LIBDIR)' 'includedir=$(INCDIR)' '' \
	    'Name: egofuse-io' 'Description: egofuse io library (static): glTF, images, devices' \
	    'Version: $(SOVERSION)' 'Requires: egofuse' 'Requires.private: $(IO_PKGS)' \
	    'Cflags: -I$${includedir}' 'Libs: -L$${libdir} -legofuse_io' 'Libs.private: -lmeshoptimizer -lstdc++ -ldl' \
	    > $(DESTDIR)$(LIBDIR)/pkgconfig/egofuse-io.pc
	@echo "installed into $(DESTDIR)$(PREFIX)"

uninstall:
	rm -f $(DESTDIR)$(LIBDIR)/libegofuse.a $(DESTDIR)$(LIBDIR)/libegofuse_io.a \
	    $(DESTDIR)$(LIBDIR)/libegofuse.so $(DESTDIR)$(LIBDIR)/libegofuse.so.$(SOMAJOR) \
	    $(DESTDIR)$(LIBDIR)/libegofuse.so.$(SOVERSION) $(DESTDIR)$(PLUGINDIR)/libegofuse_oiio.so \
	    $(DESTDIR)$(BINDIR)/egofuse $(DESTDIR)$(LIBDIR)/pkgconfig/egofuse.pc \
	    $(DESTDIR)$(LIBDIR)/pkgconfig/egofuse-io.pc
	rm -rf $(DESTDIR)$(INCDIR)/egofuse
	-rmdir $(DESTDIR)$(PLUGINDIR)
# ------------------------------------------------------------ end install


-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
