# proxima - plain GNU make.  `make help` lists targets and variables.

# `make` alone builds the library and the tools.
.DEFAULT_GOAL := all

# ---- overridable ---------------------------------------------------------
CC       ?= cc
PREFIX   ?= /usr/local
DESTDIR  ?=
LIBDIR   ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
BINDIR   ?= $(PREFIX)/bin
BUILD    ?= build
OPTFLAGS ?= -O2 -g
CFLAGS   ?=
LDFLAGS  ?=
SAN      ?=
# Per-test time limit (seconds) used by the test runner.
TEST_TIMEOUT ?= 900

# ---- fixed ---------------------------------------------------------------
NAME    := proxima
VERSION := $(shell sed -n 's/^\#define PX_VERSION_STRING "\(.*\)"/\1/p' core/px_base.h)
SOMAJOR := $(firstword $(subst ., ,$(VERSION)))

# Library folders are found, not listed: every folder under a top-level
# folder that is not one of NON_LIB_DIRS or a build directory and holds .c
# or .h files (geom/nurbs, devices/backends, app, ...) is a module folder:
# its sources go into the library and it is on the include path (npm's
# node_modules are not searched).
NON_LIB_DIRS := tests tools bench fuzz examples docs python
LIB_TOP := $(filter-out $(NON_LIB_DIRS) build% $(firstword $(subst /, ,$(BUILD))),\
             $(patsubst %/,%,$(wildcard */)))
MODULE_DIRS := $(sort $(patsubst %/,%,$(dir $(shell find $(LIB_TOP) -name node_modules -prune -o -type f -name '*.[ch]' -print))))
WARN    := -Wall -Wextra -Wshadow -Wstrict-prototypes -Werror
INCS    := $(addprefix -I,$(MODULE_DIRS))
BASE_CFLAGS := -std=c11 -D_GNU_SOURCE $(WARN) $(INCS) -fvisibility=hidden -MMD -MP

ifeq ($(SAN),1)
OPTFLAGS := -O1 -g -fno-omit-frame-pointer
SANFLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all
# Setup paths must see allocation failure as NULL (PX_E_NOMEM), not abort.
export ASAN_OPTIONS ?= allocator_may_return_null=1:detect_leaks=1
export UBSAN_OPTIONS ?= print_stacktrace=1:halt_on_error=1
endif

ALL_CFLAGS := $(BASE_CFLAGS) $(OPTFLAGS) $(SANFLAGS) $(CFLAGS)
ALL_LDFLAGS := $(SANFLAGS) $(LDFLAGS)

# ---- optional parts ------------------------------------------------------
# The distance core, the loop and the control code need libc, libm and
# pthread only. Each part below is compiled in when pkg-config finds its
# library (OpenCASCADE, which has no pkg-config file, when its headers
# are installed); WITH_<PART>=0 leaves it out, WITH_DEVICES=0 every
# device back end. A part left out is replaced by its <file>_none.c, whose functions
# return PX_E_UNSUPPORTED with a message naming the missing library, and
# px_features.h says PX_HAVE_<PART> 0.
# hidapi comes as two builds with the same symbols: HIDAPI=hidraw
# (default, /dev/hidraw*) or HIDAPI=libusb.
HIDAPI   ?= hidraw
OPT_PARTS := HIDAPI LIBUSB SOCKETCAN GPIOD ASSIMP YAML OCCT XML DDS VIEW
OPT_DEVICE_PARTS := HIDAPI LIBUSB SOCKETCAN GPIOD
PKG_HIDAPI    := hidapi-$(HIDAPI)
PKG_LIBUSB    := libusb-1.0
PKG_SOCKETCAN := libsocketcan
PKG_GPIOD     := libgpiod
PKG_ASSIMP    := assimp
PKG_YAML      := yaml-0.1
PKG_XML       := libxml-2.0
PKG_DDS       := CycloneDDS
PKG_VIEW      := libwebsockets
SRC_HIDAPI    := px_hidapi.c
SRC_LIBUSB    := px_usb.c
SRC_SOCKETCAN := px_socketcan.c
SRC_GPIOD     := px_gpiod.c
SRC_ASSIMP    := px_import.c
SRC_YAML      := px_config_yaml.c
SRC_OCCT      := cad_occt.cpp
SRC_XML       := urdf_xml.c
SRC_DDS       := px_bridge_dds.c px_bridge_dev.c px_bridge_joint.c px_bridge_scene.c
SRC_VIEW      := view_lws.c
# Tests name the parts they need by these tags (PX_TEST_NEEDS, tests/run.sh).
TAG_HIDAPI    := hidapi
TAG_LIBUSB    := libusb
TAG_SOCKETCAN := libsocketcan
TAG_GPIOD     := libgpiod
TAG_ASSIMP    := assimp
TAG_YAML      := libyaml
TAG_OCCT      := occt
TAG_XML       := libxml2
TAG_DDS       := cyclonedds
TAG_VIEW      := libwebsockets
DESC_HIDAPI    := HID devices (hidapi-$(HIDAPI))
DESC_LIBUSB    := USB devices (libusb-1.0)
DESC_SOCKETCAN := CAN interface state and bitrate (libsocketcan)
DESC_GPIOD     := GPIO lines (libgpiod)
DESC_ASSIMP    := mesh files (assimp)
DESC_YAML      := YAML configs (libyaml)
DESC_OCCT      := STEP and IGES parts (OpenCASCADE)
DESC_XML       := URDF robots (libxml2)
DESC_DDS       := ROS 2 compatible DDS bridge (Cyclone DDS and its idlc)
DESC_VIEW      := the browser view server (libwebsockets)
WITH_DEVICES ?= 1
pc_have = $(shell pkg-config --exists $(1) 2>/dev/null && echo 1 || echo 0)
# OpenCASCADE: its headers, the toolkits the importer links (C++, so the
# C++ runtime with them) and the C++ compile flags.
OCCT_INC := /usr/include/opencascade
OCCT_PART_LIBS := -lTKXSBase -lTKSTEP -lTKSTEPBase -lTKSTEPAttr -lTKSTEP209 -lTKIGES \
  -lTKShHealing -lTKTopAlgo -lTKBRep -lTKGeomAlgo -lTKGeomBase -lTKG3d -lTKG2d -lTKMath \
  -lTKernel -lstdc++
# Cyclone DDS: its library and the IDL compiler that turns bridge/idl/
# into C (cyclonedds-tools).
IDLC ?= $(shell command -v idlc 2>/dev/null)
have_part = $(if $(filter OCCT,$(1)),$(if $(wildcard $(OCCT_INC)/Standard.hxx),1,0),\
  $(if $(filter DDS,$(1)),$(if $(IDLC),$(call pc_have,$(PKG_DDS)),0),\
  $(call pc_have,$(PKG_$(1)))))
# Found once per make (a sub-make after `make deps` looks again).
$(foreach p,$(OPT_PARTS),$(if $(filter undefined,$(origin WITH_$(p))),\
  $(eval WITH_$(p) := $(if $(and $(filter $(p),$(OPT_DEVICE_PARTS)),$(filter 0,$(WITH_DEVICES))),0,$(call have_part,$(p))))))
OPT_ON   := $(foreach p,$(OPT_PARTS),$(if $(filter 1,$(WITH_$(p))),$(p)))
PKGS     := $(foreach p,$(OPT_ON),$(PKG_$(p)))
# The file of each part that this build leaves out.
OPT_OUT_SRC := $(foreach p,$(OPT_PARTS),$(if $(filter 1,$(WITH_$(p))),\
                 $(addsuffix _none.c,$(basename $(SRC_$(p)))),$(SRC_$(p))))
# Asked when a recipe runs, not when this file is read.
PKG_CFLAGS = $(if $(PKGS),$(shell pkg-config --cflags $(PKGS)))
PKG_LIBS   = $(if $(PKGS),$(shell pkg-config --libs $(PKGS)))
# Libraries of the parts without a pkg-config file (also in proxima.pc).
OPT_LIBS := $(if $(filter 1,$(WITH_OCCT)),$(OCCT_PART_LIBS))
LIBS    = $(PKG_LIBS) $(OPT_LIBS) -lm -lpthread
CXX_WARN := $(filter-out -Wstrict-prototypes,$(WARN))
ALL_CXXFLAGS = -std=c++17 -D_GNU_SOURCE $(CXX_WARN) $(INCS) -isystem $(OCCT_INC) \
  -fvisibility=hidden -MMD -MP $(OPTFLAGS) $(SANFLAGS) $(CXXFLAGS)

# ---- sources -------------------------------------------------------------
LIB_SRC  := $(filter-out $(addprefix %/,$(OPT_OUT_SRC)),\
              $(foreach d,$(MODULE_DIRS),$(wildcard $(d)/*.c)))
# C++ library files: an optional part's bridge to a C++ library.
LIB_CXX_SRC := $(filter-out $(addprefix %/,$(OPT_OUT_SRC)),\
              $(foreach d,$(MODULE_DIRS),$(wildcard $(d)/*.cpp)))
LIB_OBJ  := $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC)) \
            $(patsubst %.cpp,$(BUILD)/obj/%.o,$(LIB_CXX_SRC))
PUB_HDRS := $(filter-out %internal.h,$(foreach d,$(MODULE_DIRS),$(wildcard $(d)/px*.h)))
# The DDS bridge's message types: bridge/idl/*.idl compiled by idlc at
# build time into $(BUILD)/gen/bridge/ (C types and topic descriptors,
# never in the tree), their objects into the library.
DDS_IDL   := $(wildcard bridge/idl/*.idl)
DDS_GEN   := $(BUILD)/gen/bridge
DDS_GEN_H := $(patsubst bridge/idl/%.idl,$(DDS_GEN)/%.h,$(DDS_IDL))
DDS_GEN_OBJ := $(patsubst bridge/idl/%.idl,$(BUILD)/obj/gen-bridge/%.o,$(DDS_IDL))
ifeq ($(WITH_DDS),1)
LIB_OBJ  += $(DDS_GEN_OBJ)
endif

# tests/ mirrors the tree: the test of geom/track/ is tests/geom/track/
# test_*.c, the shared fixtures are in tests/support/. The binaries stay
# flat, $(BUILD)/tests/test_<name> (test names are unique), in the order
# of their names; tests/vm/ holds the VM suite's own programs.
TEST_SUPPORT_DIR := tests/support
TEST_SUPPORT_SRC := $(wildcard $(TEST_SUPPORT_DIR)/px_*.c)
TEST_SUPPORT_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(TEST_SUPPORT_SRC))
# C++ fixtures (OpenCASCADE references) in builds with OpenCASCADE, in
# the tests' library: linked only into the tests that call them.
TEST_SUPPORT_CXX_SRC := $(if $(filter 1,$(WITH_OCCT)),$(wildcard $(TEST_SUPPORT_DIR)/px_*.cpp))
TEST_SUPPORT_CXX_OBJ := $(patsubst %.cpp,$(BUILD)/obj/%.o,$(TEST_SUPPORT_CXX_SRC))
test_find = $(shell find tests -name 'test_*.$(1)' -not -path '$(TEST_SUPPORT_DIR)/*' \
              -not -path 'tests/vm/*' | awk -F/ '{ print $$NF, $$0 }' | sort | cut -d' ' -f2)
TEST_SRC := $(call test_find,c)
TEST_BIN := $(foreach t,$(TEST_SRC),$(BUILD)/tests/$(basename $(notdir $(t))))
TEST_SH  := $(call test_find,sh)
ifneq ($(words $(TEST_BIN)),$(words $(sort $(TEST_BIN))))
$(error two test sources under tests/ have the same name: $(sort $(TEST_SRC)))
endif
# Test hooks: the sources with test switches and hook functions are built
# a second time with -DPX_TEST_HOOKS into TEST_LIB, which the tests and
# benches link; the shipped library has none (geom/math/math_internal.h).
TEST_HOOK_SRC := $(filter geom/track/%.c geom/dist/spiece_solve.c geom/brep/brep_cos.c \
                           geom/brep/brep_compose.c geom/pair/pair_nurbs.c,$(LIB_SRC))
TEST_HOOK_OBJ := $(patsubst %.c,$(BUILD)/obj-hooks/%.o,$(TEST_HOOK_SRC))
TEST_LIB := $(BUILD)/lib/lib$(NAME)-test.a

TOOL_SUPPORT_SRC := $(wildcard tools/tool_*.c)
TOOL_SUPPORT_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(TOOL_SUPPORT_SRC))
# proxima-run reports the heap calls made after setup with the tests'
# counter when one is loaded: the tests preload it as its own shared
# object (ALLOC_SO, never installed), so the installed tools keep the
# system allocator. Sanitizer builds count through the sanitizer's hooks,
# which a preloaded object cannot reach: there the tools link it, and the
# tests' leak suppressions for OpenCASCADE's toolkits (px_lsan.c).
ALLOC_SO := $(BUILD)/lib/lib$(NAME)-alloc-count.so
ifeq ($(SAN),1)
TOOL_SUPPORT_OBJ += $(BUILD)/obj/$(TEST_SUPPORT_DIR)/px_alloc_count.o \
                    $(BUILD)/obj/$(TEST_SUPPORT_DIR)/px_lsan.o
endif
TOOL_SRC := $(wildcard tools/proxima-*.c)
# C++ tools (the CAD part generator) in builds with OpenCASCADE.
TOOL_CXX_SRC := $(if $(filter 1,$(WITH_OCCT)),$(wildcard tools/proxima-*.cpp))
TOOL_BIN := $(patsubst tools/%.c,$(BUILD)/bin/%,$(TOOL_SRC)) \
            $(patsubst tools/%.cpp,$(BUILD)/bin/%,$(TOOL_CXX_SRC))
# The modelling toolkits the part generator builds its solids with.
OCCT_MODEL_LIBS := -lTKOffset -lTKFillet -lTKFeat -lTKBool -lTKBO -lTKPrim
$(BUILD)/bin/proxima-cadgen: LIBS += $(OCCT_MODEL_LIBS)
# A tool's own parts: tools/<name>_*.c go into proxima-<name> alone
# (tools/run_*.c into proxima-run); tools/tool_*.c into every tool.
tool_parts = $(patsubst %.c,$(BUILD)/obj/%.o,$(wildcard tools/$(1)_*.c))
TOOL_PART_OBJ := $(foreach t,$(TOOL_SRC:tools/proxima-%.c=%),$(call tool_parts,$(t)))
$(foreach t,$(TOOL_SRC:tools/proxima-%.c=%),\
  $(eval $(BUILD)/bin/proxima-$(t): $(call tool_parts,$(t))))

# examples/*.c: programs that see only the public headers, as a user's
# code does (<proxima/px_*.h> from $(BUILD)/include, the installed layout).
EXAMPLE_SRC := $(wildcard examples/*.c)
EXAMPLE_BIN := $(patsubst examples/%.c,$(BUILD)/examples/%,$(EXAMPLE_SRC))
INC_DIR     := $(BUILD)/include
INC_STAMP   := $(INC_DIR)/$(NAME)/.stamp
# Generated: what this build has; on every compile's include path.
FEATURES_H  := $(BUILD)/gen/px_features.h

BENCH_SRC := $(wildcard bench/bench_*.c)
BENCH_BIN := $(patsubst bench/%.c,$(BUILD)/bench/%,$(BENCH_SRC))
# C++ comparisons against OpenCASCADE, built only where its headers are.
OCCT_LIBS := -lTKGeomAlgo -lTKGeomBase -lTKG3d -lTKG2d -lTKMath -lTKernel
CXX_BENCH_SRC := $(if $(wildcard $(OCCT_INC)/Standard.hxx),$(wildcard bench/bench_*_occt.cpp))
# The CAD parts' comparison needs the library's STEP reader too.
CXX_BENCH_SRC := $(filter-out $(if $(filter 1,$(WITH_OCCT)),,bench/bench_brep_occt.cpp),$(CXX_BENCH_SRC))
CXX_BENCH_BIN := $(patsubst bench/%.cpp,$(BUILD)/bench/%,$(CXX_BENCH_SRC))

STATIC_LIB := $(BUILD)/lib/lib$(NAME).a
SHARED_LIB := $(BUILD)/lib/lib$(NAME).so.$(VERSION)
PC_FILE    := $(BUILD)/lib/pkgconfig/$(NAME).pc

# Debian packages that building and testing need (see `make deps`).
DEB_PACKAGES := gcc make libc6-dev pkg-config
DEB_PACKAGES += libhidapi-dev libusb-1.0-0-dev libsocketcan-dev libgpiod-dev
# static linking of hidapi and libusb needs libudev.so
DEB_PACKAGES += libudev-dev
# bridge/: the DDS bridge (Cyclone DDS and its IDL compiler).
DEB_PACKAGES += cyclonedds-dev cyclonedds-tools
# view/: the browser view's server (HTTP and WebSocket).
DEB_PACKAGES += libwebsockets-dev
# Debian packages the benchmarks compare against (installed by `make bench`;
# a benchmark whose reference is missing says so and still runs).
BENCH_DEB_PACKAGES := rt-tests g++ libocct-modeling-algorithms-dev
# (its headers include the Extrema and geometry headers of the data module,
# which the algorithms package does not depend on)
BENCH_DEB_PACKAGES += libocct-modeling-data-dev
# bench_models compares with FCL through a C++ program (bench/fcl_models.cpp).
BENCH_DEB_PACKAGES += libfcl-dev
# config/: YAML loader.
DEB_PACKAGES += libyaml-dev
# python/: the Python package and its example's plots.
DEB_PACKAGES += python3 python3-dev python3-cffi python3-numpy python3-matplotlib
# geom/: mesh and point-cloud import.
DEB_PACKAGES += libassimp-dev
# robot/: URDF files.
DEB_PACKAGES += libxml2-dev
# geom/brep/: STEP and IGES import (OpenCASCADE 7.6) and its C++ compiler.
DEB_PACKAGES += g++ libocct-data-exchange-dev libocct-modeling-algorithms-dev
DEB_PACKAGES += libocct-modeling-data-dev libocct-foundation-dev

FORCE:

.PHONY: FORCE all lib tools examples tests benches run-benches bench-section test bench sanitize install uninstall \
        clean help deps check-deps fcl-bench

all: lib tools examples

# Keep objects made by chained pattern rules.
.SECONDARY:

lib: $(STATIC_LIB) $(SHARED_LIB) $(PC_FILE)

tools: $(TOOL_BIN)

tests: $(TEST_BIN) $(if $(filter 1,$(SAN)),,$(ALLOC_SO))

examples: $(EXAMPLE_BIN)

benches: $(BENCH_BIN) $(CXX_BENCH_BIN)

# ---- Python package (python/) ---------------------------------------------
# The proxima module for Debian's python3 (cffi, API mode: python/build_ext.py
# says why), built into $(BUILD)/python (PYTHONPATH=$(BUILD)/python) when
# that python has cffi, numpy and its C headers; WITH_PYTHON=0 leaves it
# out. Not in sanitizer builds: an ASan library cannot load into a plain
# interpreter.
PYTHON ?= $(firstword $(wildcard /usr/bin/python3) python3)
PY_PROBE := import cffi, numpy, os, sysconfig, sys; \
  sys.exit(not os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")))
ifeq ($(origin WITH_PYTHON),undefined)
WITH_PYTHON := $(if $(filter 1,$(SAN)),0,$(shell $(PYTHON) -c '$(PY_PROBE)' 2>/dev/null && echo 1 || echo 0))
endif
PY_SRC := python/build_ext.py $(wildcard python/proxima/*.py python/proxima/_pxpy.[ch])
PY_STAMP := $(BUILD)/python/proxima/__init__.py
PY_BUILD = $(PYTHON) python/build_ext.py $(1) $(addprefix --include ,$(MODULE_DIRS) $(BUILD)/gen) \
  --libdir $(BUILD)/lib --rpath $(2) --cflags "$(WARN) $(OPTFLAGS) $(CFLAGS)"
# Debian's interpreter searches <prefix>/lib/python3.X/dist-packages.
PY_VER = $(shell $(PYTHON) -c 'import sys; print("%d.%d" % sys.version_info[:2])')
PYDIR ?= $(LIBDIR)/python$(PY_VER)/dist-packages

.PHONY: python
python: $(PY_STAMP)
ifeq ($(WITH_PYTHON),1)
all: python
endif

$(PY_STAMP): $(PY_SRC) $(SHARED_LIB) $(PUB_HDRS)
	$(call PY_BUILD,$(BUILD)/python,$(abspath $(BUILD)/lib))

# ---- the view page (view/web/) ---------------------------------------------
# The browser side of the view (docs/view-page.md): npm packages in
# view/web/node_modules (three.js, uPlot; esbuild bundles, playwright-core
# and ws serve the browser tests), installed by `make deps` or `make
# view-web`; view/web/build.mjs bundles the page into $(BUILD)/view/web.
# `all` builds it when the packages are installed, fetching nothing; the
# browser tests (tests/view/) skip without them or chromium.
NODE ?= node
NPM  ?= npm
VIEW_WEB      := view/web
VIEW_WEB_OUT  := $(BUILD)/view/web
VIEW_WEB_MODS := $(VIEW_WEB)/node_modules/.package-lock.json
VIEW_WEB_SRC  := $(wildcard $(VIEW_WEB)/src/*) $(VIEW_WEB)/build.mjs
DEB_PACKAGES += nodejs chromium chromium-driver

.PHONY: view-web
view-web: $(VIEW_WEB_MODS)
	@$(MAKE) --no-print-directory $(VIEW_WEB_OUT)/index.html
ifneq ($(wildcard $(VIEW_WEB_MODS)),)
all: $(VIEW_WEB_OUT)/index.html
endif

# npm ci installs exactly the lock file's versions.
$(VIEW_WEB_MODS): $(VIEW_WEB)/package.json $(wildcard $(VIEW_WEB)/package-lock.json)
	cd $(VIEW_WEB) && if [ -f package-lock.json ]; then $(NPM) ci --no-audit --no-fund; \
	  else $(NPM) install --no-audit --no-fund; fi
	@touch $@

$(VIEW_WEB_OUT)/index.html: $(VIEW_WEB_SRC) $(VIEW_WEB_MODS)
	$(NODE) $(VIEW_WEB)/build.mjs --out $(VIEW_WEB_OUT)

# ---- rules ---------------------------------------------------------------
$(BUILD)/obj/%.o: %.c | $(FEATURES_H)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -I$(BUILD)/gen $(PKG_CFLAGS) -fPIC -c $< -o $@

# idlc writes a .c and a .h per IDL file; the includes between the IDL
# files become includes between the headers.
$(DDS_GEN)/%.c $(DDS_GEN)/%.h: bridge/idl/%.idl $(DDS_IDL)
	@mkdir -p $(DDS_GEN)
	$(IDLC) -x final -Ibridge/idl -o $(DDS_GEN) $<

$(BUILD)/obj/gen-bridge/%.o: $(DDS_GEN)/%.c $(DDS_GEN_H)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -I$(DDS_GEN) $(PKG_CFLAGS) -fPIC -c $< -o $@

# What includes the generated headers (the bridge, its tests) sees them.
ifeq ($(WITH_DDS),1)
$(BUILD)/obj/bridge/%.o $(BUILD)/obj-hooks/bridge/%.o $(BUILD)/obj/tests/bridge/%.o $(BUILD)/obj/bench/bench_teleop.o: ALL_CFLAGS += -I$(DDS_GEN)
$(patsubst %.c,$(BUILD)/obj/%.o,$(wildcard bridge/*.c tests/bridge/*.c) bench/bench_teleop.c): | $(DDS_GEN_H)
endif

$(BUILD)/obj/%.o: %.cpp | $(FEATURES_H)
	@mkdir -p $(dir $@)
	$(CXX) $(ALL_CXXFLAGS) -I$(BUILD)/gen -fPIC -c $< -o $@

# The library is made again when the set of optional parts changes.
$(STATIC_LIB): $(LIB_OBJ) $(FEATURES_H)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $(filter %.o,$^)

$(SHARED_LIB): $(LIB_OBJ) $(FEATURES_H)
	@mkdir -p $(dir $@)
	$(CC) -shared -Wl,-soname,lib$(NAME).so.$(SOMAJOR) $(ALL_LDFLAGS) -o $@ $(filter %.o,$^) $(LIBS)
	ln -sf lib$(NAME).so.$(VERSION) $(BUILD)/lib/lib$(NAME).so.$(SOMAJOR)
	ln -sf lib$(NAME).so.$(SOMAJOR) $(BUILD)/lib/lib$(NAME).so

# Regenerated every time: it records PREFIX/LIBDIR, which may change per call.
$(PC_FILE): FORCE
	@mkdir -p $(dir $@)
	printf '%s\n' 'prefix=$(PREFIX)' 'libdir=$(LIBDIR)' 'includedir=$(INCLUDEDIR)' '' \
	  'Name: $(NAME)' \
	  'Description: real-time distance queries and control loops for haptics and robotics' \
	  'Version: $(VERSION)' \
	  'Requires.private: $(PKGS)' \
	  'Cflags: -I$${includedir}' \
	  'Libs: -L$${libdir} -l$(NAME)' \
	  'Libs.private: $(OPT_LIBS) -lm -lpthread' > $@

$(BUILD)/obj-hooks/%.o: %.c | $(FEATURES_H)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -DPX_TEST_HOOKS -I$(BUILD)/gen $(PKG_CFLAGS) -fPIC -c $< -o $@

$(TEST_LIB): $(filter-out $(patsubst %.c,$(BUILD)/obj/%.o,$(TEST_HOOK_SRC)),$(LIB_OBJ)) $(TEST_HOOK_OBJ) \
             $(TEST_SUPPORT_CXX_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@
	ar rcs $@ $^

# One rule per test: $(BUILD)/tests/test_x from tests/<folder>/test_x.c.
define TEST_RULE
$(BUILD)/tests/$(basename $(notdir $(1))): $(BUILD)/obj/$(1:.c=.o) $$(TEST_SUPPORT_OBJ) $$(TEST_LIB)
	@mkdir -p $$(dir $$@)
	$$(CC) $$(ALL_LDFLAGS) -o $$@ $$< $$(TEST_SUPPORT_OBJ) $$(TEST_LIB) $$(LIBS)
endef
$(foreach t,$(TEST_SRC),$(eval $(call TEST_RULE,$(t))))

$(BUILD)/bin/%: $(BUILD)/obj/tools/%.o $(TOOL_SUPPORT_OBJ) $(STATIC_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_LDFLAGS) -o $@ $(filter %.o,$^) $(STATIC_LIB) $(LIBS)

# Initial-exec TLS: the per-thread count must not make the dynamic
# loader allocate on a thread's first heap call.
$(ALLOC_SO): $(TEST_SUPPORT_DIR)/px_alloc_count.c $(TEST_SUPPORT_DIR)/px_alloc_count.h
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -D_GNU_SOURCE $(WARN) $(OPTFLAGS) $(CFLAGS) -I$(TEST_SUPPORT_DIR) -fPIC -shared \
	  -ftls-model=initial-exec $(LDFLAGS) -o $@ $<

# The public headers, flat under $(INC_DIR)/$(NAME)/ as they install.
$(INC_STAMP): $(PUB_HDRS) $(FEATURES_H)
	@rm -rf $(dir $@) && mkdir -p $(dir $@)
	cp $(PUB_HDRS) $(FEATURES_H) $(dir $@)
	@touch $@

# What this build has (rewritten only when that changes).
$(FEATURES_H): FORCE
	@mkdir -p $(dir $@)
	@{ printf '%s\n' '/* px_features.h - the optional parts of this build of proxima' \
	    ' * (generated by make): 1 compiled in, 0 left out (its functions' \
	    ' * return PX_E_UNSUPPORTED). */' '#ifndef PX_FEATURES_H' '#define PX_FEATURES_H'; \
	  $(foreach p,$(OPT_PARTS),printf '#define PX_HAVE_%s %s\n' $(p) $(WITH_$(p));) \
	  printf '%s\n' '#endif'; } > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv $@.tmp $@; fi

$(BUILD)/obj/examples/%.o: examples/%.c $(INC_STAMP)
	@mkdir -p $(dir $@)
	$(CC) -std=c11 $(WARN) -I$(INC_DIR) $(OPTFLAGS) $(SANFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/examples/%: $(BUILD)/obj/examples/%.o $(STATIC_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_LDFLAGS) -o $@ $< $(STATIC_LIB) $(LIBS)

$(BUILD)/bench/%_occt: bench/%_occt.cpp $(STATIC_LIB)
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -O2 -g -Wall -Wextra -Werror -Wno-deprecated-declarations \
	  -isystem $(OCCT_INC) $(INCS) -o $@ $< $(STATIC_LIB) $(OCCT_LIBS) $(LIBS)

# The CAD parts against OpenCASCADE: the parts come from the part
# generator, their checks from the tests' OpenCASCADE reference.
$(BUILD)/bench/bench_brep_occt: bench/bench_brep_occt.cpp $(TEST_SUPPORT_DIR)/px_occt_ref.cpp \
                                $(TEST_SUPPORT_DIR)/px_occt_ref.h bench/bench_util.h $(STATIC_LIB) \
                                $(BUILD)/bin/proxima-cadgen
	@mkdir -p $(dir $@)
	$(CXX) -std=c++17 -O2 -g -Wall -Wextra -Werror -Wno-deprecated-declarations \
	  -isystem $(OCCT_INC) $(INCS) -I$(TEST_SUPPORT_DIR) -o $@ $< $(TEST_SUPPORT_DIR)/px_occt_ref.cpp \
	  $(STATIC_LIB) $(OCCT_LIBS) $(LIBS)

$(BUILD)/bench/%: $(BUILD)/obj/bench/%.o $(TEST_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_LDFLAGS) -o $@ $< $(TEST_LIB) $(LIBS)

# The HID back end reports which hidapi build it was linked with.
$(BUILD)/obj/devices/backends/px_hidapi.o: ALL_CFLAGS += -DPX_HIDAPI_DRIVER=\"$(HIDAPI)\"

# Test and bench sources also see the test harness headers.
$(BUILD)/obj/tests/%.o $(BUILD)/obj/bench/%.o $(BUILD)/obj/tools/%.o: ALL_CFLAGS += -I$(TEST_SUPPORT_DIR) -Itools
$(BUILD)/obj/tests/%.o $(BUILD)/obj/bench/%.o: ALL_CFLAGS += -DPX_TEST_HOOKS

# ---- top-level actions ---------------------------------------------------
# `make deps` first; a second make then finds the optional parts it may
# just have installed.
test: deps
	@$(MAKE) --no-print-directory test-run

# A test that needs a part this build left out skips, saying which.
.PHONY: test-run
test-run: all tests
	@BUILD=$(BUILD) SAN=$(SAN) CC="$(CC)" MAKE="$(MAKE)" TEST_TIMEOUT=$(TEST_TIMEOUT) \
	  PX_WITHOUT="$(foreach p,$(OPT_PARTS),$(if $(filter 1,$(WITH_$(p))),,$(TAG_$(p)))) $(if $(filter 1,$(WITH_PYTHON)),,python)" \
	  PYTHON="$(PYTHON)" sh tests/run.sh $(TEST_BIN) $(TEST_SH)

bench: all
	@sh tools/install-deps.sh $(BENCH_DEB_PACKAGES) || echo "make bench: continuing without $(BENCH_DEB_PACKAGES)"
	@# A second make sees the reference libraries just installed.
	@$(MAKE) --no-print-directory benches
	@$(MAKE) --no-print-directory fcl-bench || echo "make bench: FCL reference not built"
	@$(MAKE) --no-print-directory run-benches

# Teleoperation on loopback: the two example processes linked by DDS.
.PHONY: teleop
teleop: all
	@sh tools/teleop.sh --duration-s $(or $(TELEOP_S),10) $(BUILD)

# Runs every benchmark and writes docs/benchmarks.md from their output.
run-benches:
	@BUILD=$(BUILD) PYTHON=$(PYTHON) sh bench/report.sh $(BENCH_BIN) $(CXX_BENCH_BIN) \
	  $(if $(filter 1,$(WITH_PYTHON)),bench/bench_python.sh)

# Runs one benchmark and replaces its section of docs/benchmarks.md, the
# rest of the report kept: make bench-section BENCH=bench_track
bench-section: benches
	@test -n "$(BENCH)" || { echo "make bench-section: BENCH=name, e.g. bench_track"; exit 1; }
	@BUILD=$(BUILD) PYTHON=$(PYTHON) BENCH_SECTIONS=1 sh bench/report.sh \
	  $(if $(filter bench_python,$(BENCH)),bench/bench_python.sh,$(BUILD)/bench/$(BENCH))

# FCL reference program for bench_models, only where FCL is installed
# (checked when it runs, after `make bench` installed the packages).
fcl-bench:
	@if pkg-config --exists fcl 2>/dev/null; then \
	  $(MAKE) --no-print-directory $(BUILD)/bench/fcl_models; \
	else echo "make bench: FCL not installed: bench_models runs without it"; fi

$(BUILD)/bench/fcl_models: bench/fcl_models.cpp bench/models_common.h $(TEST_SUPPORT_DIR)/mesh_gen.h
	@mkdir -p $(dir $@)
	$(CXX) -O2 -g -std=c++14 -I$(TEST_SUPPORT_DIR) -Ibench $$(pkg-config --cflags fcl) $< -o $@ $$(pkg-config --libs fcl)

sanitize:
	$(MAKE) BUILD=$(BUILD)/san SAN=1 test

# The main job: a simulated haptic device exploring NURBS surfaces and a
# mesh at 1 kHz for RUN_SECONDS, live status line, summary, CSV and plots.
RUN_CONFIG  ?= config/examples/haptic_sim.yaml
RUN_SECONDS ?= 10
RUN_ARGS    ?=
# The live view's port ([ADDR:]PORT; empty: no view). A port taken is
# said and the run goes on without the view.
RUN_VIEW    ?= 8765
.PHONY: run
# The run counts its heap calls after setup with the tests' counter.
run: deps
	@$(MAKE) --no-print-directory all $(if $(filter 1,$(SAN)),,$(ALLOC_SO))
	$(if $(filter 1,$(SAN)),,LD_PRELOAD=$(abspath $(ALLOC_SO))) $(BUILD)/bin/proxima-run $(RUN_CONFIG) --duration-s $(RUN_SECONDS) \
	  --summary-json $(BUILD)/run-summary.json $(if $(RUN_VIEW),--view $(RUN_VIEW)) $(RUN_ARGS)

deps:
	@sh tools/install-deps.sh $(DEB_PACKAGES)
	@# Debian's npm only where node came without one.
	@command -v $(NPM) >/dev/null 2>&1 || sh tools/install-deps.sh npm
	@$(MAKE) --no-print-directory $(VIEW_WEB_MODS) >/dev/null || \
	  echo "make deps: the view page's npm packages are not installed: its browser tests skip" >&2

install: lib tools $(FEATURES_H)
	install -d $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(INCLUDEDIR)/$(NAME) $(DESTDIR)$(BINDIR)
	install -m 644 $(STATIC_LIB) $(DESTDIR)$(LIBDIR)/
	install -m 755 $(SHARED_LIB) $(DESTDIR)$(LIBDIR)/
	ln -sf lib$(NAME).so.$(VERSION) $(DESTDIR)$(LIBDIR)/lib$(NAME).so.$(SOMAJOR)
	ln -sf lib$(NAME).so.$(SOMAJOR) $(DESTDIR)$(LIBDIR)/lib$(NAME).so
	install -m 644 $(PUB_HDRS) $(FEATURES_H) $(DESTDIR)$(INCLUDEDIR)/$(NAME)/
	install -m 644 $(PC_FILE) $(DESTDIR)$(LIBDIR)/pkgconfig/
	$(if $(TOOL_BIN),install -m 755 $(TOOL_BIN) $(DESTDIR)$(BINDIR)/)
ifeq ($(WITH_PYTHON),1)
	$(call PY_BUILD,$(BUILD)/python-install,$(LIBDIR))
	install -d $(DESTDIR)$(PYDIR)/proxima
	install -m 644 $(BUILD)/python-install/proxima/*.py $(DESTDIR)$(PYDIR)/proxima/
	install -m 755 $(BUILD)/python-install/proxima/*.so $(DESTDIR)$(PYDIR)/proxima/
endif

uninstall:
	rm -f $(DESTDIR)$(LIBDIR)/lib$(NAME).a $(DESTDIR)$(LIBDIR)/lib$(NAME).so*
	rm -f $(DESTDIR)$(LIBDIR)/pkgconfig/$(NAME).pc
	rm -rf $(DESTDIR)$(INCLUDEDIR)/$(NAME) $(DESTDIR)$(PYDIR)/proxima
	rm -f $(addprefix $(DESTDIR)$(BINDIR)/,$(notdir $(TOOL_BIN)))

clean:
	rm -rf $(BUILD)

help:
	@echo 'Targets:'
	@echo '  all        static and shared library (build/lib), tools (build/bin),'
	@echo '             examples (build/examples), the Python package'
	@echo '             (build/python, WITH_PYTHON=$(WITH_PYTHON)); the default target'
	@echo '  test       install missing packages, build, run the whole test suite'
	@echo '  bench      build and run the benchmarks'
	@echo '  bench-section BENCH=name  run one benchmark, replace its section of docs/benchmarks.md'
	@echo '  teleop     the teleoperation examples, master and follower on loopback (TELEOP_S=10)'
	@echo '  sanitize   the test suite built with AddressSanitizer + UBSan'
	@echo '  run        build, then run proxima-run on RUN_CONFIG for RUN_SECONDS (default config, 10 s),'
	@echo '             the live view on RUN_VIEW=$(RUN_VIEW)'
	@echo '  fuzz       build fuzz/fuzz_*.c with libFuzzer, run each FUZZ_SECONDS=$(FUZZ_SECONDS) s'
	@echo '  soak       SOAK_CYCLES=$(SOAK_CYCLES) loop cycles with faults in virtual time'
	@echo '  memcheck   the tools under valgrind memcheck on sample inputs'
	@echo '  stress     hostile geometry with the large cases (PX_STRESS=1)'
	@echo '  install    library, headers, tools and proxima.pc under DESTDIR/PREFIX'
	@echo '  uninstall  remove what install put there'
	@echo '  deps       install the Debian packages building and testing need'
	@echo '  view-web   install the npm packages of the view page, build it into $(BUILD)/view/web'
	@echo '  clean      remove the build directory'
	@echo '  help       this text'
	@echo 'Variables (make VAR=value):'
	@echo '  CC=$(CC) PREFIX=$(PREFIX) DESTDIR=$(DESTDIR) LIBDIR=$(LIBDIR)'
	@echo '  INCLUDEDIR=$(INCLUDEDIR) BINDIR=$(BINDIR) BUILD=$(BUILD)'
	@echo '  PYTHON=$(PYTHON) PYDIR=$(PYDIR) (where install puts the proxima package)'
	@echo '  OPTFLAGS=$(OPTFLAGS) CFLAGS=$(CFLAGS) LDFLAGS=$(LDFLAGS)'
	@echo '  TEST_TIMEOUT=$(TEST_TIMEOUT) (seconds per test binary)'
	@echo '  HIDAPI=$(HIDAPI) (hidraw or libusb: the hidapi build to link)'
	@echo 'Optional parts (compiled in when pkg-config finds them; WITH_<PART>=0'
	@echo 'leaves one out, WITH_DEVICES=0 every device back end):'
	@$(foreach p,$(OPT_PARTS),printf '  %-16s %s\n' 'WITH_$(p)=$(WITH_$(p))' '$(DESC_$(p))';)
	@echo 'Environment for tests: PX_TEST_SEED=<n> replays a seed,'
	@echo '  PX_TEST_ONLY=<name> runs one test of a binary.'

# One variable's value, for scripts: `make -s print-OPT_PARTS`
# (tests/test_build_parts.sh reads the parts and their tags).
print-%:
	@echo '$($*)'

# ---- fuzzing (clang + libFuzzer) -----------------------------------------
# Every fuzz/fuzz_<name>.c is a libFuzzer target. `make fuzz` builds the
# library once with clang's fuzzer instrumentation plus ASan and UBSan
# ($(BUILD)/fuzz/obj), links each target into $(BUILD)/fuzz/fuzz_<name>
# and runs it for FUZZ_SECONDS on a copy of its seed corpus
# fuzz/corpus/<name>/ (new inputs stay in $(BUILD)/fuzz/corpus-<name>,
# crash and hang artifacts in $(BUILD)/fuzz/). FUZZ_TARGETS=codec,can
# picks targets. Fails when a target found something. Skipped, with a
# message, when FUZZ_CC cannot link -fsanitize=fuzzer (the Debian
# packages in FUZZ_DEB_PACKAGES are installed first when missing).
# The same sources built with the normal compiler against fuzz/replay.c
# ($(BUILD)/fuzz-replay/fuzz_<name>) replay fuzz/regress/<name>/ and the
# seeds inside `make test` and `make sanitize`.
FUZZ_CC      ?= clang
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?=
# Extra libFuzzer flags, e.g. FUZZ_ARGS='-seed=1 -runs=20000' for a
# repeatable pass (CI).
FUZZ_ARGS    ?=
FUZZ_DEB_PACKAGES := clang libclang-rt-dev
FUZZ_SRC     := $(wildcard fuzz/fuzz_*.c)
FUZZ_NAMES   := $(patsubst fuzz/fuzz_%.c,%,$(FUZZ_SRC))
comma        := ,
FUZZ_RUN     := $(if $(FUZZ_TARGETS),$(subst $(comma), ,$(FUZZ_TARGETS)),$(FUZZ_NAMES))
FUZZ_BIN     := $(patsubst %,$(BUILD)/fuzz/fuzz_%,$(FUZZ_NAMES))
# C++ parts and the DDS bridge are built with their C stand-ins there
# (the fuzz targets reach neither C++ nor DDS, whose generated types are
# not in the fuzz build); a DDS file without a _none.c of its own has its
# stand-ins in another's (as in a build without DDS).
FUZZ_LIB_SRC := $(foreach f,$(LIB_SRC),$(if $(filter $(addprefix %/,$(SRC_DDS)),$(f)),$(wildcard $(f:.c=_none.c)),$(f)))
FUZZ_LIB_OBJ := $(patsubst %.c,$(BUILD)/fuzz/obj/%.o,$(FUZZ_LIB_SRC) $(LIB_CXX_SRC:.cpp=_none.c))
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=undefined
FUZZ_FLAGS   := -std=c11 -D_GNU_SOURCE $(WARN) $(INCS) -g -O1 \
                -Wno-unused-function -fno-omit-frame-pointer $(FUZZ_SAN)
FUZZ_REPLAY_BIN := $(patsubst %,$(BUILD)/fuzz-replay/fuzz_%,$(FUZZ_NAMES))

$(BUILD)/fuzz/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_FLAGS) -fsanitize=fuzzer-no-link -MMD -MP $(PKG_CFLAGS) -c $< -o $@

$(BUILD)/fuzz/libproxima-fuzz.a: $(FUZZ_LIB_OBJ)
	rm -f $@
	ar rcs $@ $^

$(BUILD)/fuzz/fuzz_%: $(BUILD)/fuzz/obj/fuzz/fuzz_%.o $(BUILD)/fuzz/libproxima-fuzz.a
	$(FUZZ_CC) $(FUZZ_SAN) -fsanitize=fuzzer -o $@ $^ $(LIBS)

$(BUILD)/fuzz-replay/fuzz_%: $(BUILD)/obj/fuzz/fuzz_%.o $(BUILD)/obj/fuzz/replay.o $(STATIC_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_LDFLAGS) -o $@ $^ $(LIBS)

# The replay programs are test programs: built by `tests`, run by `test`.
tests: $(FUZZ_REPLAY_BIN)
TEST_BIN += $(FUZZ_REPLAY_BIN)

.PHONY: fuzz fuzz-build
fuzz-build: $(FUZZ_BIN)

fuzz:
	@sh tools/install-deps.sh $(FUZZ_DEB_PACKAGES) || echo "fuzz: could not install $(FUZZ_DEB_PACKAGES)"
	@if ! printf 'int LLVMFuzzerTestOneInput(const char *d, unsigned long n);\nint LLVMFuzzerTestOneInput(const char *d, unsigned long n) { (void)d; (void)n; return 0; }\n' | \
	    $(FUZZ_CC) -x c -fsanitize=fuzzer - -o /dev/null >/dev/null 2>&1; then \
	  echo "fuzz: skipped: '$(FUZZ_CC)' cannot link -fsanitize=fuzzer (install clang with libFuzzer)"; \
	  exit 0; \
	fi; \
	$(MAKE) --no-print-directory fuzz-build || exit 1; \
	failed=""; \
	for short in $(FUZZ_RUN); do \
	  name=fuzz_$$short; \
	  mkdir -p $(BUILD)/fuzz/corpus-$$short; \
	  echo "== $$name: $(FUZZ_SECONDS) s"; \
	  $(BUILD)/fuzz/$$name -max_total_time=$(FUZZ_SECONDS) -timeout=10 \
	    -rss_limit_mb=2048 -artifact_prefix=$(BUILD)/fuzz/$$name- \
	    -print_final_stats=1 $(FUZZ_ARGS) $(BUILD)/fuzz/corpus-$$short \
	    $$(test -d fuzz/corpus/$$short && echo fuzz/corpus/$$short) \
	    > $(BUILD)/fuzz/$$name.log 2>&1 || failed="$$failed $$short"; \
	  grep -E '^(stat::number_of_executed_units|stat::peak_rss_mb|#[0-9]+ +DONE)' $(BUILD)/fuzz/$$name.log | tr '\n' ' '; echo; \
	done; \
	if [ -n "$$failed" ]; then \
	  echo "fuzz: FOUND PROBLEMS in:$$failed (logs: $(BUILD)/fuzz/fuzz_<name>.log; artifacts: $(BUILD)/fuzz/fuzz_<name>-*)"; \
	  exit 1; \
	fi; \
	echo "fuzz: no crash, leak or hang in $(FUZZ_SECONDS) s per target: $(FUZZ_RUN)"

# ---- soak, memcheck, stress (reliability) ----------------------------------
# `make soak`: tests/rt/test_soak.c for SOAK_CYCLES cycles on the virtual
# clock (make test runs 200000 of them). `make memcheck`: the tools under
# valgrind on sample inputs (tests/memcheck.sh). `make stress`: the hostile
# geometry tests with their large cases (PX_STRESS=1).
SOAK_CYCLES ?= 10000000
.PHONY: soak memcheck stress
soak: $(BUILD)/tests/test_soak
	PX_SOAK_CYCLES=$(SOAK_CYCLES) $(BUILD)/tests/test_soak

memcheck: all
	@sh tools/install-deps.sh valgrind || echo "memcheck: could not install valgrind"
	BUILD=$(BUILD) sh tests/memcheck.sh

stress: $(BUILD)/tests/test_hostile
	PX_STRESS=1 $(BUILD)/tests/test_hostile

-include $(LIB_OBJ:.o=.d) $(TEST_HOOK_OBJ:.o=.d) $(TEST_SUPPORT_OBJ:.o=.d) $(TOOL_SUPPORT_OBJ:.o=.d) \
  $(TOOL_PART_OBJ:.o=.d)
-include $(patsubst %.c,$(BUILD)/obj/%.d,$(TEST_SRC) $(TOOL_SRC) $(BENCH_SRC) $(EXAMPLE_SRC))
-include $(patsubst %.cpp,$(BUILD)/obj/%.d,$(TOOL_CXX_SRC) $(TEST_SUPPORT_CXX_SRC))
-include $(patsubst %.c,$(BUILD)/obj/%.d,$(FUZZ_SRC) fuzz/replay.c)
