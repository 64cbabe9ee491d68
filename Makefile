# robin_contact: contact of elastic bodies (any number, frictionless or with friction) by Robin domain decomposition.
# Plain Makefile, explicit module dependencies. `make -j2` works.
#   make            build bin/robin_contact (installs missing Debian packages first)
#   make run        build and solve inputs/default.nml
#   make check      build and run every test (last line: N passed, M failed)
#   make meshes     regenerate the shipped Gmsh meshes inputs/gmsh/*.msh from their .geo
#   make DEBUG=1    checked build (-fcheck=all, FP traps, backtrace) in build/debug,
#                   bin/robin_contact_debug; `make check DEBUG=1` tests that one
#   make MPI=1      the MPI binary bin/robin_contact_mpi (mpif90/mpicc, MUMPS) in build/mpi;
#                   `make check` builds it too where mpif90 and libmumps-dev are installed

FC      ?= gfortran
CC      ?= gcc
PYTHON  ?= /usr/bin/python3
DEBUG   ?= 0
MPI     ?= 0
ifeq ($(origin FC),default)
FC := gfortran
endif
ifeq ($(MPI),1)
FC := mpif90
CC := mpicc
endif

ifeq ($(MPI),1)
BUILD   := build/mpi
FOPT    := -O2 -g
COPT    := -O2 -g
else ifeq ($(DEBUG),1)
BUILD   := build/debug
FOPT    := -g -O0 -fcheck=all -ffpe-trap=invalid,zero,overflow -fbacktrace
COPT    := -g -O0
else
BUILD   := build/release
FOPT    := -O2 -g
COPT    := -O2 -g
endif

HDF5_INC := /usr/include/hdf5/serial
HDF5_LIB := /usr/lib/x86_64-linux-gnu/hdf5/serial
FFLAGS  := $(FOPT) -fopenmp -ffree-line-length-none -Wall -Wno-maybe-uninitialized -Wno-compare-reals \
           -J$(BUILD) -I$(BUILD) -I$(HDF5_INC) $(EXTRA_FFLAGS)
CFLAGS  := $(COPT) -fopenmp -Wall -Iinclude -I/usr/include/suitesparse $(EXTRA_CFLAGS)
LDLIBS  := -L$(HDF5_LIB) -lhdf5_fortran -lhdf5 -lcholmod -lsuitesparseconfig -lmetis -llapack -lopenblas -lm
# The parallel environment and MUMPS: one module each, in a serial and an MPI version
# (Debian's libdmumps is linked shared: it brings its ScaLAPACK/BLACS and PORD itself).
ifeq ($(MPI),1)
MPI_ENV_SRC := src/parallel/mpi_env_mpi.f90
MUMPS_SRC   := src/linalg/mumps_iface.f90
FFLAGS  += -I/usr/include
LDLIBS  := -ldmumps -lmumps_common $(LDLIBS)
else
MPI_ENV_SRC := src/parallel/mpi_env_serial.f90
MUMPS_SRC   := src/linalg/mumps_iface_none.f90
endif

BIN     := bin
ifeq ($(MPI),1)
PROG    := $(BIN)/robin_contact_mpi
else ifeq ($(DEBUG),1)
PROG    := $(BIN)/robin_contact_debug
else
PROG    := $(BIN)/robin_contact
endif

# Library modules in data-flow order (deck -> mesh -> assembly -> factorization ->
# condensation -> contact iteration -> output).
MODS := kinds space errors clock strings digest int_hash text_scanner sorting sysinfo signals mpi_env config material_laws namelist_vars namelist_input deck_tables deck_checks deck_cross deck_render deck budget mesh mesh_topology volume_topology gmsh_msh elements elements_3d element_types lapack linop body_system supports stiffness_pattern rigid_modes assembly \
        cholmod_iface ordering banded cholesky mumps_iface factorization mprgp_options constraint_set tangent_discs mprgp_support qp_newton disc_newton mprgp smalbe nonneg_lsq mortar_chains mortar_rows mortar_segments mortar_surfaces mortar contact_interface condense contact_types contact_common friction_view floating equality_rows \
        robin_operators robin_subproblems acceleration robin_iteration monolithic error_estimate post_process h5io files history_io \
        results checkpoint fatal_errors load_history run_state run_backend serial_backend mpi_backend run_summary run_phases command_line
OBJS := $(addprefix $(BUILD)/,$(addsuffix .o,$(MODS))) $(BUILD)/cholmod_shim.o $(BUILD)/blas_tiles.o $(BUILD)/sighdl.o \
        $(BUILD)/sysinfo_shim.o $(BUILD)/files_shim.o

TESTS_F := test_errors test_deck test_mprgp test_mprgp_options test_mprgp_box test_constraint_set test_disc_set test_friction_view test_acceleration test_qp_newton test_cholesky test_factorization test_ordering test_fem test_gmsh test_mortar test_equilibrium test_contact test_files test_h5io test_floating test_digest test_rank_map test_text_scanner test_flex_rank test_result_names test_materials test_elements_3d test_mortar_3d test_box test_gmsh_3d test_frames test_robin_operators test_checkpoint test_namelist_reader test_supports
BENCH_F := bench_mprgp bench_ordering bench_ordering_3d bench_assembly_rate
TEST_BINS  := $(addprefix $(BUILD)/tests/,$(TESTS_F))
BENCH_BINS := $(addprefix $(BUILD)/bench/,$(BENCH_F))

DEPS_STAMP := build/.deps-ok
ifeq ($(MPI),1)
DEPS_STAMP := build/.deps-mpi-ok
endif
# mpif90 and MUMPS's headers present: `make check` builds and tests the MPI binary too

.PHONY: all mpi mpi-deps run check bench-mprgp bench-ordering bench-ordering-3d table1 bench bench-hertz bench-gmsh bench-mpi hard plots meshes clean deps FORCE
all: $(PROG)

# ---- system packages: install what is missing (Debian 12) --------------------
$(DEPS_STAMP): tools/install-deps.sh
	@if command -v $(FC) >/dev/null 2>&1 && command -v $(CC) >/dev/null 2>&1 \
	   && [ -f /usr/include/suitesparse/cholmod.h ] && [ -f $(HDF5_INC)/hdf5.mod ] \
	   && [ -f /usr/include/metis.h ] && [ -e /usr/lib/x86_64-linux-gnu/libopenblas.so ] \
	   && [ -e /usr/lib/x86_64-linux-gnu/liblapack.so ] && command -v pgrep >/dev/null 2>&1 \
	   && [ -x $(PYTHON) ] && $(PYTHON) -c 'import numpy, h5py, meshio, matplotlib' 2>/dev/null \
	   && command -v pvpython >/dev/null 2>&1 && command -v xvfb-run >/dev/null 2>&1; then :; \
	 else bash tools/install-deps.sh; fi
	@if [ "$(MPI)" = 1 ] && ! { command -v mpif90 >/dev/null 2>&1 && [ -f /usr/include/dmumps_struc.h ]; }; then \
	   bash tools/install-deps.sh; fi
	@mkdir -p build && touch $@
deps: $(DEPS_STAMP)

# ---- compile -------------------------------------------------------------------
# Sources are grouped by stage (src/base, input, fem, linalg, qp, contact, io; the driver at
# the top); objects and modules go flat into $(BUILD).
SRC_DIRS := src src/base src/input src/fem src/linalg src/qp src/contact src/io src/parallel src/driver
vpath %.f90 $(SRC_DIRS)
vpath %.c $(SRC_DIRS)

$(BUILD)/%.o: %.f90 | $(DEPS_STAMP)
	@mkdir -p $(BUILD)
	$(FC) $(FFLAGS) -c $< -o $@

$(BUILD)/%.o: %.c include/cholmod_shim.h include/blas_tiles.h include/sighdl.h | $(DEPS_STAMP)
	@mkdir -p $(BUILD)
	$(CC) $(CFLAGS) -c $< -o $@

# make check's MPI build (MPI=1 SHARE=build/release, the serial build made just before it):
# the modules that use neither MPI nor MUMPS, not even through another module
# (tools/mpi_free_modules.py), are the serial build's objects and module files, copied; only
# the others are compiled again with mpif90.
ifeq ($(MPI),1)
ifneq ($(SHARE),)
SHARED_MODS := $(shell $(PYTHON) tools/mpi_free_modules.py)
$(addprefix $(BUILD)/,$(addsuffix .o,$(SHARED_MODS))): $(BUILD)/%.o: $(SHARE)/%.o
	@mkdir -p $(BUILD)
	cp -p $< $@
	cp -p $(SHARE)/$*.mod $(BUILD)/$*.mod
endif
endif

# Explicit module dependencies: each object depends on the modules its source `use`s
# (tests/test_makefile_deps.py checks that these lines are exactly the real ones).
$(BUILD)/kinds.o:
$(BUILD)/errors.o:
$(BUILD)/clock.o:          $(BUILD)/kinds.o
$(BUILD)/strings.o:        $(BUILD)/kinds.o
$(BUILD)/digest.o:         $(BUILD)/errors.o
$(BUILD)/int_hash.o:       $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/strings.o
$(BUILD)/text_scanner.o:   $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/strings.o
$(BUILD)/sorting.o:
$(BUILD)/sysinfo.o:        $(BUILD)/kinds.o
$(BUILD)/signals.o:
$(BUILD)/mpi_env.o:        $(BUILD)/kinds.o $(BUILD)/errors.o
$(BUILD)/space.o:          $(BUILD)/kinds.o
$(BUILD)/config.o:         $(BUILD)/kinds.o $(BUILD)/space.o
$(BUILD)/namelist_vars.o:  $(BUILD)/kinds.o $(BUILD)/strings.o
$(BUILD)/namelist_input.o: $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/strings.o $(BUILD)/namelist_vars.o
$(BUILD)/deck_tables.o:    $(BUILD)/kinds.o $(BUILD)/namelist_vars.o $(BUILD)/config.o $(BUILD)/space.o
$(BUILD)/deck_checks.o:    $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/namelist_vars.o $(BUILD)/errors.o $(BUILD)/space.o \
                           $(BUILD)/namelist_input.o $(BUILD)/config.o $(BUILD)/deck_tables.o
$(BUILD)/material_laws.o:  $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/errors.o
$(BUILD)/deck_cross.o:     $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/strings.o $(BUILD)/sorting.o $(BUILD)/config.o $(BUILD)/deck_checks.o \
                           $(BUILD)/material_laws.o
$(BUILD)/deck_render.o:    $(BUILD)/strings.o $(BUILD)/namelist_vars.o $(BUILD)/config.o $(BUILD)/deck_tables.o
$(BUILD)/deck.o:           $(BUILD)/errors.o $(BUILD)/strings.o $(BUILD)/namelist_input.o $(BUILD)/config.o \
                           $(BUILD)/deck_checks.o $(BUILD)/deck_cross.o $(BUILD)/deck_render.o
$(BUILD)/budget.o:         $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/config.o $(BUILD)/space.o
$(BUILD)/mesh.o:           $(BUILD)/space.o $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/strings.o $(BUILD)/errors.o
$(BUILD)/mesh_topology.o:  $(BUILD)/kinds.o $(BUILD)/sorting.o $(BUILD)/errors.o $(BUILD)/config.o $(BUILD)/strings.o $(BUILD)/int_hash.o $(BUILD)/mesh.o
$(BUILD)/volume_topology.o: $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/errors.o $(BUILD)/strings.o $(BUILD)/int_hash.o \
                           $(BUILD)/sorting.o $(BUILD)/mesh.o $(BUILD)/mesh_topology.o
$(BUILD)/gmsh_msh.o:       $(BUILD)/digest.o $(BUILD)/errors.o $(BUILD)/int_hash.o $(BUILD)/kinds.o $(BUILD)/mesh.o \
                           $(BUILD)/mesh_topology.o $(BUILD)/volume_topology.o $(BUILD)/space.o $(BUILD)/strings.o \
                           $(BUILD)/text_scanner.o
$(BUILD)/elements.o:       $(BUILD)/kinds.o $(BUILD)/config.o
$(BUILD)/elements_3d.o:    $(BUILD)/kinds.o
$(BUILD)/element_types.o:  $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/elements.o $(BUILD)/elements_3d.o $(BUILD)/space.o
$(BUILD)/lapack.o:         $(BUILD)/kinds.o
$(BUILD)/linop.o:          $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/errors.o $(BUILD)/strings.o
$(BUILD)/body_system.o:    $(BUILD)/kinds.o
$(BUILD)/supports.o:       $(BUILD)/space.o $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/mesh.o $(BUILD)/body_system.o $(BUILD)/strings.o $(BUILD)/errors.o
$(BUILD)/stiffness_pattern.o: $(BUILD)/space.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/mesh.o $(BUILD)/body_system.o
$(BUILD)/rigid_modes.o:    $(BUILD)/space.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/mesh.o $(BUILD)/lapack.o $(BUILD)/body_system.o
$(BUILD)/assembly.o:       $(BUILD)/space.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/sorting.o $(BUILD)/config.o $(BUILD)/mesh.o $(BUILD)/elements_3d.o \
                           $(BUILD)/elements.o $(BUILD)/element_types.o $(BUILD)/linop.o $(BUILD)/body_system.o \
                           $(BUILD)/supports.o $(BUILD)/stiffness_pattern.o $(BUILD)/rigid_modes.o $(BUILD)/strings.o \
                           $(BUILD)/material_laws.o
$(BUILD)/ordering.o:       $(BUILD)/space.o $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/cholmod_iface.o
$(BUILD)/cholmod_iface.o:  $(BUILD)/kinds.o $(BUILD)/errors.o
$(BUILD)/banded.o:         $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/clock.o $(BUILD)/sorting.o $(BUILD)/lapack.o
$(BUILD)/cholesky.o:       $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/cholmod_iface.o $(BUILD)/banded.o \
                           $(BUILD)/ordering.o $(BUILD)/clock.o
$(BUILD)/mumps_iface.o:    $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/lapack.o
$(BUILD)/factorization.o $(BUILD)/element_types.o: FFLAGS += -Wno-unused-dummy-argument
$(BUILD)/factorization.o:  $(BUILD)/kinds.o $(BUILD)/space.o $(BUILD)/config.o $(BUILD)/cholesky.o $(BUILD)/mumps_iface.o \
                           $(BUILD)/errors.o $(BUILD)/strings.o
$(BUILD)/mprgp_options.o:  $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/signals.o $(BUILD)/errors.o
$(BUILD)/constraint_set.o: $(BUILD)/kinds.o $(BUILD)/errors.o
$(BUILD)/tangent_discs.o:  $(BUILD)/kinds.o $(BUILD)/constraint_set.o $(BUILD)/errors.o
$(BUILD)/mprgp_support.o:  $(BUILD)/kinds.o $(BUILD)/linop.o $(BUILD)/constraint_set.o
$(BUILD)/qp_newton.o:      $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/constraint_set.o
$(BUILD)/disc_newton.o:    $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/tangent_discs.o $(BUILD)/qp_newton.o
$(BUILD)/mprgp.o:          $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/errors.o $(BUILD)/linop.o $(BUILD)/mprgp_options.o \
                           $(BUILD)/constraint_set.o $(BUILD)/mprgp_support.o $(BUILD)/qp_newton.o \
                           $(BUILD)/tangent_discs.o $(BUILD)/disc_newton.o
$(BUILD)/smalbe.o:         $(BUILD)/kinds.o $(BUILD)/linop.o $(BUILD)/lapack.o $(BUILD)/mprgp.o $(BUILD)/constraint_set.o
$(BUILD)/nonneg_lsq.o:     $(BUILD)/cholesky.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/sorting.o
$(BUILD)/mortar_chains.o:  $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o
$(BUILD)/mortar_rows.o:    $(BUILD)/kinds.o
$(BUILD)/mortar_segments.o: $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/mortar_chains.o \
                           $(BUILD)/mortar_rows.o
$(BUILD)/mortar_surfaces.o: $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/mortar_rows.o
$(BUILD)/mortar.o:         $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/strings.o $(BUILD)/mortar_rows.o \
                           $(BUILD)/mortar_segments.o $(BUILD)/mortar_surfaces.o
$(BUILD)/contact_interface.o: $(BUILD)/space.o $(BUILD)/assembly.o $(BUILD)/config.o $(BUILD)/errors.o $(BUILD)/int_hash.o $(BUILD)/kinds.o \
                           $(BUILD)/mesh.o $(BUILD)/mortar.o $(BUILD)/strings.o
$(BUILD)/condense.o:       $(BUILD)/assembly.o $(BUILD)/factorization.o $(BUILD)/clock.o $(BUILD)/config.o \
                           $(BUILD)/contact_interface.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/lapack.o \
                           $(BUILD)/mesh.o $(BUILD)/ordering.o $(BUILD)/space.o
$(BUILD)/floating.o:       $(BUILD)/space.o $(BUILD)/assembly.o $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_common.o \
                           $(BUILD)/contact_interface.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/lapack.o \
                           $(BUILD)/nonneg_lsq.o $(BUILD)/strings.o
$(BUILD)/contact_types.o:  $(BUILD)/kinds.o $(BUILD)/space.o
$(BUILD)/contact_common.o: $(BUILD)/condense.o $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/kinds.o
$(BUILD)/friction_view.o:  $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/kinds.o $(BUILD)/space.o
$(BUILD)/equality_rows.o:  $(BUILD)/condense.o $(BUILD)/contact_interface.o $(BUILD)/kinds.o $(BUILD)/lapack.o \
                           $(BUILD)/linop.o $(BUILD)/nonneg_lsq.o
# the Robin operators implement one interface: not every operator needs every argument
$(BUILD)/robin_operators.o: $(BUILD)/cholesky.o $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_common.o \
                           $(BUILD)/contact_interface.o $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/lapack.o \
                           $(BUILD)/linop.o $(BUILD)/mprgp.o $(BUILD)/sorting.o $(BUILD)/strings.o
$(BUILD)/robin_operators.o: $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/linop.o $(BUILD)/lapack.o $(BUILD)/mprgp.o \
                           $(BUILD)/condense.o $(BUILD)/contact_common.o
$(BUILD)/robin_subproblems.o: $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_common.o \
                           $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/equality_rows.o \
                           $(BUILD)/kinds.o $(BUILD)/linop.o $(BUILD)/mprgp.o $(BUILD)/robin_operators.o \
                           $(BUILD)/qp_newton.o $(BUILD)/smalbe.o $(BUILD)/sorting.o $(BUILD)/constraint_set.o \
                           $(BUILD)/tangent_discs.o $(BUILD)/lapack.o $(BUILD)/disc_newton.o
$(BUILD)/acceleration.o:   $(BUILD)/kinds.o $(BUILD)/config.o $(BUILD)/lapack.o $(BUILD)/contact_types.o \
                           $(BUILD)/contact_common.o
$(BUILD)/robin_iteration.o: $(BUILD)/acceleration.o $(BUILD)/clock.o $(BUILD)/condense.o $(BUILD)/config.o \
                           $(BUILD)/contact_common.o $(BUILD)/contact_interface.o $(BUILD)/contact_types.o \
                           $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/robin_operators.o $(BUILD)/robin_subproblems.o \
                           $(BUILD)/signals.o
$(BUILD)/monolithic.o:     $(BUILD)/clock.o $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_common.o \
                           $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/equality_rows.o \
                           $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/linop.o $(BUILD)/mprgp.o $(BUILD)/smalbe.o \
                           $(BUILD)/sorting.o $(BUILD)/strings.o $(BUILD)/tangent_discs.o $(BUILD)/signals.o
$(BUILD)/error_estimate.o: $(BUILD)/cholesky.o $(BUILD)/condense.o $(BUILD)/contact_common.o \
                           $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/equality_rows.o \
                           $(BUILD)/errors.o $(BUILD)/kinds.o $(BUILD)/lapack.o $(BUILD)/linop.o $(BUILD)/monolithic.o \
                           $(BUILD)/nonneg_lsq.o $(BUILD)/constraint_set.o $(BUILD)/tangent_discs.o
$(BUILD)/post_process.o:   $(BUILD)/assembly.o $(BUILD)/body_system.o $(BUILD)/config.o $(BUILD)/contact_interface.o \
                           $(BUILD)/contact_types.o $(BUILD)/friction_view.o $(BUILD)/kinds.o $(BUILD)/mesh.o $(BUILD)/space.o
$(BUILD)/h5io.o:           $(BUILD)/kinds.o $(BUILD)/errors.o
$(BUILD)/files.o:          $(BUILD)/errors.o $(BUILD)/strings.o
$(BUILD)/history_io.o:     $(BUILD)/kinds.o $(BUILD)/errors.o $(BUILD)/contact_types.o $(BUILD)/h5io.o
$(BUILD)/results.o:        $(BUILD)/space.o $(BUILD)/body_system.o $(BUILD)/config.o $(BUILD)/contact_interface.o \
                           $(BUILD)/contact_types.o $(BUILD)/errors.o $(BUILD)/files.o $(BUILD)/floating.o \
                           $(BUILD)/h5io.o $(BUILD)/history_io.o $(BUILD)/kinds.o $(BUILD)/mesh.o \
                           $(BUILD)/post_process.o $(BUILD)/strings.o
$(BUILD)/checkpoint.o:     $(BUILD)/kinds.o $(BUILD)/space.o $(BUILD)/errors.o $(BUILD)/strings.o $(BUILD)/digest.o $(BUILD)/contact_types.o $(BUILD)/h5io.o \
                           $(BUILD)/files.o $(BUILD)/history_io.o $(BUILD)/results.o
# the driver's modules (src/driver): the route to an exit on error, the run's data, its two back-ends, its phases
$(BUILD)/fatal_errors.o:   $(BUILD)/errors.o
$(BUILD)/load_history.o:   $(BUILD)/assembly.o $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_interface.o \
                           $(BUILD)/errors.o $(BUILD)/floating.o $(BUILD)/kinds.o
$(BUILD)/run_state.o:      $(BUILD)/assembly.o $(BUILD)/clock.o $(BUILD)/condense.o $(BUILD)/config.o \
                           $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/deck.o $(BUILD)/fatal_errors.o \
                           $(BUILD)/kinds.o $(BUILD)/load_history.o $(BUILD)/mesh.o $(BUILD)/mpi_env.o $(BUILD)/results.o \
                           $(BUILD)/strings.o
$(BUILD)/run_backend.o:    $(BUILD)/config.o $(BUILD)/run_state.o
# a back-end implements every phase of the interface: not every phase needs every argument
$(BUILD)/serial_backend.o $(BUILD)/mpi_backend.o: FFLAGS += -Wno-unused-dummy-argument
$(BUILD)/serial_backend.o: $(BUILD)/assembly.o $(BUILD)/budget.o $(BUILD)/condense.o $(BUILD)/config.o \
                           $(BUILD)/contact_common.o $(BUILD)/errors.o $(BUILD)/fatal_errors.o $(BUILD)/kinds.o \
                           $(BUILD)/load_history.o $(BUILD)/mpi_env.o $(BUILD)/run_backend.o $(BUILD)/run_state.o $(BUILD)/sorting.o \
                           $(BUILD)/strings.o $(BUILD)/sysinfo.o
$(BUILD)/mpi_backend.o:    $(BUILD)/assembly.o $(BUILD)/budget.o $(BUILD)/condense.o $(BUILD)/factorization.o \
                           $(BUILD)/config.o $(BUILD)/contact_common.o $(BUILD)/contact_types.o $(BUILD)/errors.o \
                           $(BUILD)/fatal_errors.o $(BUILD)/floating.o $(BUILD)/kinds.o $(BUILD)/mpi_env.o \
                           $(BUILD)/run_backend.o $(BUILD)/run_state.o $(BUILD)/strings.o $(BUILD)/sysinfo.o
$(BUILD)/run_summary.o:    $(BUILD)/condense.o $(BUILD)/config.o $(BUILD)/contact_common.o $(BUILD)/space.o \
                           $(BUILD)/contact_interface.o $(BUILD)/contact_types.o $(BUILD)/errors.o \
                           $(BUILD)/friction_view.o $(BUILD)/kinds.o $(BUILD)/mesh.o $(BUILD)/namelist_vars.o \
                           $(BUILD)/run_state.o $(BUILD)/strings.o $(BUILD)/sysinfo.o
$(BUILD)/run_phases.o:     $(BUILD)/assembly.o $(BUILD)/budget.o $(BUILD)/checkpoint.o $(BUILD)/cholmod_iface.o $(BUILD)/elements_3d.o $(BUILD)/space.o \
                           $(BUILD)/clock.o $(BUILD)/config.o $(BUILD)/contact_common.o $(BUILD)/contact_interface.o \
                           $(BUILD)/contact_types.o $(BUILD)/error_estimate.o $(BUILD)/errors.o $(BUILD)/fatal_errors.o \
                           $(BUILD)/files.o \
                           $(BUILD)/floating.o $(BUILD)/gmsh_msh.o $(BUILD)/kinds.o $(BUILD)/load_history.o \
                           $(BUILD)/mesh.o $(BUILD)/monolithic.o $(BUILD)/mpi_backend.o $(BUILD)/mpi_env.o \
                           $(BUILD)/post_process.o $(BUILD)/results.o $(BUILD)/robin_iteration.o $(BUILD)/run_backend.o $(BUILD)/run_state.o \
                           $(BUILD)/run_summary.o $(BUILD)/serial_backend.o $(BUILD)/signals.o $(BUILD)/sorting.o \
                           $(BUILD)/strings.o $(BUILD)/sysinfo.o
$(BUILD)/command_line.o:   $(BUILD)/errors.o $(BUILD)/fatal_errors.o $(BUILD)/deck.o $(BUILD)/config.o $(BUILD)/sysinfo.o $(BUILD)/mpi_env.o
$(BUILD)/sysinfo_shim.o:   include/sysinfo_shim.h
$(BUILD)/files_shim.o:     include/files_shim.h
$(BUILD)/robin_contact.o:  $(OBJS)

# the two modules with a serial and an MPI source (MPI_ENV_SRC, MUMPS_SRC above)
$(BUILD)/mpi_env.o: $(MPI_ENV_SRC) | $(DEPS_STAMP)
	@mkdir -p $(BUILD)
	$(FC) $(FFLAGS) -c $< -o $@
$(BUILD)/mumps_iface.o: $(MUMPS_SRC) | $(DEPS_STAMP)
	@mkdir -p $(BUILD)
	$(FC) $(FFLAGS) -c $< -o $@

# ---- link ----------------------------------------------------------------------
$(BUILD)/robin_contact: $(BUILD)/robin_contact.o $(OBJS)
	$(FC) $(FFLAGS) -o $@ $^ $(LDLIBS)

$(PROG): $(BUILD)/robin_contact FORCE
	@mkdir -p $(BIN)
	@cmp -s $< $@ || { cp $< $@.tmp && mv -f $@.tmp $@; }

# Unit test programs (tests/unit/test_*.f90, built into $(BUILD)/tests) share the helper
# module tests/unit/testing.f90; the benchmark programs (bench/*.f90) go to $(BUILD)/bench.
TEST_SUPPORT := $(BUILD)/tests/testing.o

$(TEST_SUPPORT): tests/unit/testing.f90 $(OBJS)
	@mkdir -p $(BUILD)/tests
	$(FC) $(FFLAGS) -c $< -o $@

$(BUILD)/tests/%.o: tests/unit/%.f90 $(OBJS) $(TEST_SUPPORT)
	@mkdir -p $(BUILD)/tests
	$(FC) $(FFLAGS) -c $< -o $@

$(BUILD)/bench/%.o: bench/%.f90 $(OBJS) $(TEST_SUPPORT)
	@mkdir -p $(BUILD)/bench
	$(FC) $(FFLAGS) -c $< -o $@

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(OBJS) $(TEST_SUPPORT)
	$(FC) $(FFLAGS) -o $@ $< $(OBJS) $(TEST_SUPPORT) $(LDLIBS)

$(BUILD)/bench/%: $(BUILD)/bench/%.o $(OBJS) $(TEST_SUPPORT)
	$(FC) $(FFLAGS) -o $@ $< $(OBJS) $(TEST_SUPPORT) $(LDLIBS)

# ---- user targets ----------------------------------------------------------------
run: $(PROG)
	@mkdir -p results
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PROG) inputs/default.nml

# make check runs the MPI tests too: it installs OpenMPI and MUMPS first where they are missing
# (tools/install-deps.sh; without root it prints the command and test_mpi skips)
# test_regression compares with a reference stored by the release build: to 1e-12; the checked
# build (-O0 rounds differently) within ten times each run's a posteriori bound
# the benchmark programs are built too (not run), so an interface change cannot leave them behind
# the build runs on every core (-j nproc) unless the caller gave -j already
CHECK_JOBS = $(if $(findstring -j,$(MAKEFLAGS)),,-j$(shell nproc 2>/dev/null || echo 2))
check: mpi-deps
	@$(MAKE) --no-print-directory $(CHECK_JOBS) $(PROG) $(TEST_BINS) $(BENCH_BINS)
	@rm -f $(BUILD)/mpi-build.status; \
	if command -v mpif90 >/dev/null 2>&1 && [ -f /usr/include/dmumps_struc.h ]; then \
	  echo "check: building bin/robin_contact_mpi beside the first tests (log: $(BUILD)/mpi-build.log)"; \
	  ( nice -n 10 $(MAKE) --no-print-directory $(CHECK_JOBS) MPI=1 $(if $(filter 1,$(DEBUG)),,SHARE=$(BUILD)) all \
	      > $(BUILD)/mpi-build.log 2>&1; echo $$? > $(BUILD)/mpi-build.status ) & \
	  export MPI_BUILD_STATUS=$(BUILD)/mpi-build.status; \
	fi; \
	BUILD=$(BUILD) BIN=$(PROG) PYTHON=$(PYTHON) bash tests/run_tests.sh

mpi-deps:
	@if ! { command -v mpif90 >/dev/null 2>&1 && [ -f /usr/include/dmumps_struc.h ]; }; then \
	   bash tools/install-deps.sh || echo "check: OpenMPI/MUMPS not installed: test_mpi will skip"; fi

mpi:
	$(MAKE) MPI=1 all

bench-mprgp: $(BENCH_BINS)
	$(BUILD)/bench/bench_mprgp

# the ordering ladder: metis / amd / nd, 128x64 ... 1024x512, 1 and 2 threads (about 6 min)
bench-ordering: $(PROG) $(BENCH_BINS)
	$(PYTHON) bench/bench_ordering.py --bin $(PROG) --bench $(BUILD)/bench/bench_ordering

# the orderings of a solid body: METIS on the node graph (what 'nd' gives a solid body), METIS
# on the DOF graph, CHOLMOD's own analysis, on the cubes 10^3 ... 40^3 (CUBES=10,15,20,25,30,40),
# one process each; results/bench_ordering_3d.csv and Markdown tables (about 10 min, 3.5 GB at 40^3)
CUBES ?= 10,15,20,25,30,40
bench-ordering-3d: $(BUILD)/bench/bench_ordering_3d
	$(PYTHON) bench/bench_ordering_3d.py --bench $(BUILD)/bench/bench_ordering_3d --k $(CUBES)

table1: $(PROG)
	$(PYTHON) tools/table1.py --bin $(PROG) --csv results/table1.csv

hard: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) tools/hard.py --bin $(PROG)

# Cattaneo-Mindlin in 3D against Mindlin on three meshes gmsh makes (a sphere on a block, a/R
# about 0.02, a/h about 6, 8 and 11; up to about 220k DOFs): exits 1 unless the finest mesh
# gives the stick radius (fitted to the shear) within 3% and the ring-averaged shear within 5%
# (tools/cattaneo3d_study.py; about 1.5 min, 3.1 GB)
.PHONY: cattaneo3d
cattaneo3d: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) tools/cattaneo3d_study.py --bin $(PROG) --check

bench: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) bench/bench.py --bin $(PROG)
	$(PYTHON) bench/plot_bench.py results/bench.csv

# The Gmsh ladder beside the structured one: the paper's scene as unstructured triangles
# (inputs/gmsh/bench_paper_tri.geo, meshed by gmsh into results/bench_gmsh/, h = 0.02 ...
# 0.0025: 20k ... 1.27M DOFs per body), time per phase; results/bench_gmsh.csv
# The Hertz ladder of inputs/hertz_force.nml at a/h = 64 and 256 (meshes by gmsh into
# results/bench_hertz/, about 2 min); HERTZ_N=64,256,512 adds the 4M-DOF level (6 min of
# meshing, 7 GB)
HERTZ_N ?= 64,256
bench-hertz: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) bench/bench_hertz.py --bin $(PROG) --gmsh $(GMSH) --n $(HERTZ_N)

bench-gmsh: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) bench/bench_gmsh.py --bin $(PROG) --gmsh $(GMSH) --structured

# Hertz in 3D, a ladder of meshes of inputs/sphere_block.nml's sphere on a block (meshes by
# gmsh into results/bench_hertz3d/; hc = 0.01, 0.005, 0.0035: up to about 2 x 120k DOFs, a few
# minutes); HERTZ3D_HC=0.01,0.005,0.0035,0.0028 adds about 2 x 235k DOFs (12 GB)
# HERTZ3D_SLAVE=2 makes the block the slave, HERTZ3D_METHOD=monolithic solves in one piece,
# HERTZ3D_MU=0.3 gives the pair Coulomb friction
HERTZ3D_HC ?= 0.01,0.005,0.0035
HERTZ3D_SLAVE ?= 0
HERTZ3D_METHOD ?= robin
HERTZ3D_MU ?= 0
.PHONY: bench-hertz3d
bench-hertz3d: $(PROG)
	OMP_NUM_THREADS=$${OMP_NUM_THREADS:-2} $(PYTHON) bench/bench_hertz3d.py --bin $(PROG) --gmsh $(GMSH) --hc $(HERTZ3D_HC) \
	  --slave $(HERTZ3D_SLAVE) --method $(HERTZ3D_METHOD) --mu $(HERTZ3D_MU)

# The MPI binary beside the serial one: the paper's scene at 1024x512 per body,
# serial CHOLMOD and MUMPS at -np 2, 4, 8 (oversubscribed here), time per phase and the
# largest per-rank peak memory; then the largest body per path (CHOLMOD, -np 2, -np 4) by a
# ladder (about 25 min); results/bench_mpi.csv and Markdown tables
bench-mpi: $(PROG)
	$(MAKE) MPI=1 all
	$(PYTHON) bench/bench_mpi.py --bin $(PROG) --mpi-bin bin/robin_contact_mpi --ladder

# Many-body assemblies: outer iterations against the length of a stack of N blocks (each Robin
# operator with and without Anderson, against monolithic), time and memory per phase for 32,
# 128, 512 blocks of 64x64 cells as columns of 8, and 1 against 2 threads on 64 blocks (11-15
# min, most of it waiting for a quiet machine); results/bench_bodies.csv and Markdown tables
.PHONY: bench-bodies
bench-bodies: $(PROG)
	$(PYTHON) bench/bench_bodies.py --bin $(PROG)

# Friction: the paper's scene at 128x64 ... 1024x512 per body, frictionless against Coulomb
# (mu 0.3) and Tresca, monolithic and each Robin operator: time per phase, outer/inner counts,
# memory, error against monolithic (about 20 min); results/bench_friction.csv and Markdown tables
# the inner solvers on the bolted lap joint (inputs/lap_joint.nml), 1 + 1 and 1 + 20 steps,
# Robin and monolithic (about 3 min; MPRGP alone on 1 + 1 steps only)
.PHONY: bench-assemblies
bench-assemblies: $(PROG)
	$(PYTHON) bench/bench_assemblies.py --bin $(PROG)

.PHONY: bench-friction
bench-friction: $(PROG)
	$(PYTHON) bench/bench_friction.py --bin $(PROG) --repeat 2

# CalculiX 2.20 beside robin_contact on the same tetrahedra: Hertz's sphere on a block
# (inputs/sphere_block.nml, hc = 0.02 and 0.01), P, a, p0 against Hertz and wall times
# (tools/ccx_hertz3d.py, about 2 min). Needs ccx: apt-get install -y calculix-ccx (not
# installed by tools/install-deps.sh; make check does not use it)
.PHONY: ccx-hertz3d
ccx-hertz3d: $(PROG)
	$(PYTHON) tools/ccx_hertz3d.py --bin $(PROG)

plots: $(PROG)
	BIN=$(PROG) PYTHON=$(PYTHON) bash tools/make_plots.sh

# The Gmsh meshes of inputs/gmsh are shipped (make check reads them without gmsh); this
# regenerates them from their .geo where gmsh is installed.
GMSH      ?= gmsh
GMSH_MSH  := $(GMSH) -2 -format msh41 -v 2
meshes:
	@if ! command -v $(GMSH) >/dev/null 2>&1; then \
	   echo "meshes: gmsh is not installed (apt-get install gmsh); the shipped inputs/gmsh/*.msh are kept"; \
	 else \
	   set -ex; cd inputs/gmsh; \
	   $(GMSH_MSH) paper.geo -o paper.msh; \
	   $(GMSH_MSH) patch.geo -o patch.msh; \
	   $(GMSH_MSH) patch_mixed.geo -o patch_mixed.msh; \
	   for h in 0.04 0.02 0.01 0.005; do $(GMSH_MSH) -setnumber h $$h hertz.geo -o hertz_h$$h.msh; done; \
	   for h in 0.04 0.02 0.01 0.005; do $(GMSH_MSH) -setnumber h $$h hertz_force.geo -o hertz_force_h$$h.msh; done; \
	   $(GMSH_MSH) pin_hole.geo -o pin_hole.msh; \
	   $(GMSH_MSH) cylinders.geo -o cylinders.msh; \
	   $(GMSH_MSH) shrink_fit.geo -o shrink_fit.msh; \
	   $(GMSH_MSH) -setnumber h 0.00025 coated_punch.geo -o coated_punch.msh; \
	   for h in 0.02 0.01 0.005; do $(GMSH_MSH) -setnumber h $$h sphere_flat.geo -o sphere_flat_h$$h.msh; done; \
	   for n in 8 16 32; do $(GMSH_MSH) -setnumber n $$n cattaneo_disc.geo -o cattaneo_disc_a$$n.msh; done; \
	   for n in 12:18 24:36 48:72; do nu=$${n%:*}; nl=$${n#*:}; \
	     $(GMSH_MSH) -setnumber nu $$nu -setnumber nl $$nl paper_nonmatching.geo -o paper_nonmatching_$${nu}_$${nl}.msh; \
	   done; \
	   $(GMSH) -3 -format msh41 -v 2 blocks_3d.geo -o blocks_3d.msh; \
	   for h in 0.02 0.01; do $(GMSH) -3 -format msh41 -v 2 -setnumber hc $$h sphere_block.geo -o sphere_block_h$$h.msh; done; \
	 fi

clean:
	rm -rf build bin

.SECONDARY:
