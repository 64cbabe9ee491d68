!> Result files: one HDF5 file per run, written whole or not at all (temporary
!! name in the same folder, then rename), and XDMF 3 files beside it so that
!! ParaView opens every body and contact line directly, and meshio reads each.
!!
!! `/contact` holds the rows of all contact pairs stacked; `/contact/pair_<k>` the rows of
!! pair k alone, with the ids of its two bodies. In the plane a contact grid is a polyline
!! through its rows; in space a surface, the faces of the slave's contact group whose every
!! node carries a row (`faces`).
!!
!! The fields come computed (post_process's result_fields_t: the contact rows' view, their
!! pressures and tangential part, each body's stresses, contact pressure and reactions);
!! this module orders, names and writes them.
!!
!! Every numeric dataset has a string attribute `units` (the deck's unit names: length,
!! stress, force/length for the nodal contact force in 2D, '1' for pure numbers and
!! counts, 's' for wall times); the root has `unit_length`, `unit_force`, `unit_stress`.
module results
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use, intrinsic :: iso_c_binding, only: c_loc, c_long_long
  use kinds, only: wp
  use space, only: NDIM, NCOMP, NSTRESS
  use hdf5, only: hid_t, hsize_t, haddr_t
  use h5io, only: file_open, file_close, group_open, group_close, write_dset, write_attr, write_attr_list, &
                  reserve_dset
  use history_io, only: write_history
  use files, only: temp_name, run_id, replace_suffix, base_name, ensure_parent_dir, remove_file, &
                   write_text, commit_files, data_open, data_write, data_close
  use config, only: deck_t, ELEM_Q1, ELEM_P1, ELEM_MIXED, ELEM_HEX8, ELEM_TET4, element_names, FACTOR_CHOICES, FRICTION_NONE, &
                    XDMF_PER_BODY, XDMF_COLLECTION, XDMF_PER_BODY_MAX, MAT_ISOTROPIC, contact_cfg_t, pair_oriented, &
                    side_names, BC_CONTACT, METHOD_CHOICES, program_version
  use strings, only: word, i2s, text_buffer_t
  use mesh, only: mesh_t, file_order, file_cells, file_dof, group_index
  use body_system, only: body_system_t
  use contact_interface, only: interface_t, pair_rows, row_directions
  use contact_types, only: contact_result_t, status_name
  use post_process, only: result_fields_t, contact_fields_t, body_fields_t
  use floating, only: free_list
  use errors, only: error_t, ERR_IO
  implicit none (type, external)
  private

  !> Wall-time breakdown of a run [s] and memory.
  type, public :: timing_t
    real(wp) :: assemble = 0.0_wp             !< assembly [s]
    real(wp) :: factor = 0.0_wp               !< factorization [s]
    real(wp) :: condense = 0.0_wp             !< interface condensation [s]
    real(wp) :: iterate = 0.0_wp              !< contact iteration and displacement recovery [s]
    real(wp) :: output = 0.0_wp               !< writing the result [s]
    real(wp) :: total = 0.0_wp                !< whole run [s]
    real(wp) :: peak_rss_mb = 0.0_wp          !< peak resident memory [MiB]
    real(wp) :: factor_mb = 0.0_wp            !< memory of the two Cholesky factors [MiB]
    !> the dense-kernel tiles of the bodies' factorizations, which idle threads may run
    !! (blas_tiles.c; 0: every kernel ran whole)
    real(wp) :: factor_tiles = 0.0_wp
    integer :: ranks = 1                      !< MPI processes of the run (1: the serial binary)
  end type timing_t

  !> One load step's result (&solver load_steps): its stage and load factor, its contact
  !! solution and the bodies' displacements.
  type, public :: step_result_t
    integer :: stage = 1                        !< the stage it ramps
    real(wp) :: load_factor = 1.0_wp            !< k/N_s of its stage's loads [-]
    type(contact_result_t) :: res               !< its contact solution, status and counts
    real(wp), allocatable :: u(:, :)            !< (maxndof, bodies) full displacements [length]
  end type step_result_t

  public :: write_results, result_files, per_body_files, body_group_name

  !> The faces of one pair's contact surface (in space).
  type :: faces_t
    !> (4, nf) the vertices of each face as rows of the pair, 0-based from its first row,
    !! counter-clockwise seen from outside the slave body; a triangle's fourth is -1
    integer, allocatable :: f(:, :)
  end type faces_t

  !> The datasets of a body whose data are written beside the HDF5 library (`body_data`),
  !! in the order they are created.
  integer, parameter :: BD_COORDINATES = 1, BD_DISPLACEMENT = 2, BD_GEOMETRY = 3, BD_DISPLACEMENT_XYZ = 4, &
                        BD_CELLS = 5, BD_TOPOLOGY = 6, BD_BODY_ID = 7, BD_STRESS = 8, BD_SXX = 9, &
                        BD_VON_MISES = 15, BD_PRESSURE = 16, BD_REACTION = 17, BD_REACTION_XYZ = 18, &
                        BD_COUNT = 18

contains

  !> Write the HDF5 result and its XDMF companions, each under a temporary name of this
  !! run first, and commit them together (`commit_files`: companions first, the HDF5 file
  !! last) only when all are complete. Otherwise err (ERR_IO, naming the file and what
  !! failed); then the files of an earlier result at these names are as they were, and no
  !! temporary file is left. The HDF5 library is called from one thread; with two, the
  !! other writes the companions and, body by body, takes the fields of each body from
  !! `fields` (post_process's body_fields) and writes their data into the storage the first
  !! has reserved.
  subroutine write_results(file, d, msh, sys, fields, u, tm, err, steps, threads, stale)
    character(len=*), intent(in) :: file               !< result path (.h5)
    type(deck_t), intent(in) :: d                      !< the effective deck
    type(mesh_t), intent(in) :: msh(:)                 !< meshes
    type(body_system_t), intent(in) :: sys(:)          !< systems (DOF maps)
    !> the fields to write (post_process's prepare_fields, with the load steps add_step's)
    type(result_fields_t), intent(in) :: fields
    real(wp), intent(in) :: u(:, :)                    !< (maxndof, bodies) full displacements
    type(timing_t), intent(in) :: tm                   !< timing breakdown
    type(error_t), intent(out) :: err                  !< the failure, if any
    !> the load steps' results (several steps: /steps, and the XDMF files a time series;
    !! fields%step(k) the fields of steps(k))
    type(step_result_t), intent(in), optional :: steps(:)
    integer, intent(in), optional :: threads           !< threads to write with (default 1)
    !> the files of an earlier result at this name that this one lacks, removed once it is
    !! in place (`<stem>_body<a>.xdmf` beyond its bodies, `<stem>_contact<k>.xdmf` beyond its pairs)
    integer, intent(out), optional :: stale
    character(len=len_trim(file) + 32), allocatable :: name(:)
    real(wp), allocatable :: times(:)
    character(len=len_trim(file) + 160), allocatable :: tmp(:)
    character(len=len_trim(file) + 16) :: stale_pre(2)
    character(len=:), allocatable :: h5, id
    type(error_t) :: st, commit
    integer :: k, nb, np, nf, nt, nstale
    integer :: nbf, npf   ! the bodies and pairs with an XDMF file of their own
    logical :: ok, per_body
    type(faces_t), allocatable :: surf(:)

    ! the file shows one entry per contact node: the normal rows (fields%itf), with friction
    ! the tangential part of each node beside them
    call contact_surfaces(d, msh, fields%itf, surf)
    nb = size(msh)
    np = fields%itf%npair
    call ensure_parent_dir(file)
    per_body = per_body_files(d%output%xdmf, nb, np)
    nbf = merge(nb, 0, per_body)
    npf = merge(np, 1, per_body)
    call result_files(file, nbf, npf, name)
    nf = size(name)
    allocate (tmp(nf))
    do k = 1, nf
      tmp(k) = temp_name(name(k))
    end do
    allocate (times(0))
    if (present(steps)) then
      if (size(steps) > 0) times = [(step_time(steps(k)), k=1, size(steps))]
    end if
    nt = 1
    if (present(threads)) nt = max(1, threads)
    id = run_id()
    h5 = base_name(file)
    ok = .false.
    !$omp parallel num_threads(nt)
    !$omp single
    !$omp task
    call write_companions(ok)
    !$omp end task
    if (size(times) > 0) then
      call write_h5(tmp(1), d, msh, sys, fields, fields%itf, surf, fields%last%res, u, tm, id, st, steps)
    else
      call write_h5(tmp(1), d, msh, sys, fields, fields%itf, surf, fields%last%res, u, tm, id, st)
    end if
    !$omp end single
    !$omp end parallel
    if (st%failed()) then
      call err%set(ERR_IO, 'cannot write '//trim(file)//' ('//st%text()//')')
      call remove_temps()
      return
    end if
    if (.not. ok) then
      call err%set(ERR_IO, 'cannot write the XDMF files beside '//trim(file))
      call remove_temps()
      return
    end if
    ! companions first, the HDF5 file last: it appears only with its XDMF files; then the
    ! companions of an earlier result with more bodies or pairs, which this one lacks
    stale_pre(1) = replace_suffix(trim(file), '.h5', '_body')
    stale_pre(2) = replace_suffix(trim(file), '.h5', '_contact')
    call commit_files(tmp(nf:1:-1), name(nf:1:-1), commit, stale_pre, [nbf + 1, merge(npf + 1, 1, npf > 1)], '.xdmf', &
                      nstale)
    if (commit%failed()) call err%set(ERR_IO, 'cannot write '//trim(file)//': '//commit%message)
    if (present(stale)) stale = nstale

  contains

    !> The XDMF files tmp(2:): every body and contact line (ParaView), all contact lines,
    !! and one grid each of the nbf bodies and npf pairs (meshio); one pair: its line is all of /contact, the
    !! grid 'contact'.
    subroutine write_companions(done)
      logical, intent(out) :: done   !< all written
      integer :: a, q
      type(error_t) :: werr
      if (np == 1) then
        call write_text(tmp(2), xdmf_text([(a, a=1, nb)], [0], h5, msh, fields%itf, surf, id, times), werr)
      else
        call write_text(tmp(2), xdmf_text([(a, a=1, nb)], [(q, q=1, np)], h5, msh, fields%itf, surf, id, times), werr)
      end if
      do a = 1, nbf
        if (.not. werr%failed()) &
          call write_text(tmp(2 + a), xdmf_text([a], [integer ::], h5, msh, fields%itf, surf, id, times), werr)
      end do
      if (.not. werr%failed()) call write_text(tmp(3 + nbf), xdmf_text([integer ::], [0], h5, msh, fields%itf, surf, id, times), werr)
      if (npf > 1) then
        do q = 1, npf
          if (.not. werr%failed()) &
            call write_text(tmp(3 + nbf + q), xdmf_text([integer ::], [q], h5, msh, fields%itf, surf, id, times), werr)
        end do
      end if
      done = .not. werr%failed()
    end subroutine write_companions

    subroutine remove_temps()
      integer :: j
      do j = 1, size(tmp)
        call remove_file(tmp(j))
      end do
    end subroutine remove_temps

  end subroutine write_results

  !> The HDF5 group of body a, 'body<a>' (any number of digits: no fixed-length name).
  pure function body_group_name(a) result(g)
    integer, intent(in) :: a   !< the body
    character(len=:), allocatable :: g
    g = 'body'//i2s(a)
  end function body_group_name

  !> Whether a result of nb bodies and np pairs has one XDMF file per body and per pair
  !! beside its collection, for the deck's `&output xdmf` (config XDMF_*); without them its
  !! files are result_files(file, 0, 1).
  pure logical function per_body_files(mode, nb, np)
    integer, intent(in) :: mode, nb, np
    select case (mode)
    case (XDMF_PER_BODY)
      per_body_files = .true.
    case (XDMF_COLLECTION)
      per_body_files = .false.
    case default
      per_body_files = nb <= XDMF_PER_BODY_MAX .and. np <= XDMF_PER_BODY_MAX
    end select
  end function per_body_files

  !> The files of a result with nb per-body and np per-pair XDMF files: the HDF5 file,
  !! <stem>.xdmf, <stem>_body<a>.xdmf for a = 1..nb, <stem>_contact.xdmf, and for np > 1
  !! <stem>_contact<k>.xdmf for k = 1..np (nb = 0, np = 1: the collection files alone;
  !! per_body_files decides).
  subroutine result_files(file, nb, np, name)
    character(len=*), intent(in) :: file
    integer, intent(in) :: nb, np
    character(len=*), allocatable, intent(out) :: name(:)
    integer :: k
    allocate (name(3 + nb + merge(np, 0, np > 1)))
    name(1) = file
    name(2) = replace_suffix(file, '.h5', '.xdmf')
    do k = 1, nb
      name(2 + k) = replace_suffix(file, '.h5', '_body'//i2s(k)//'.xdmf')
    end do
    name(3 + nb) = replace_suffix(file, '.h5', '_contact.xdmf')
    if (np > 1) then
      do k = 1, np
        name(3 + nb + k) = replace_suffix(file, '.h5', '_contact'//i2s(k)//'.xdmf')
      end do
    end if
  end subroutine result_files

  !> The HDF5 result file `path`, whole; st records the first failure. The large datasets of
  !! each body are created with their storage reserved, and a task per body (`body_data`)
  !! takes their data from `fields` and writes them there; all tasks end before this returns.
  subroutine write_h5(path, d, msh, sys, fields, itf, surf, res, u, tm, run_id, st, steps)
    character(len=*), intent(in) :: path
    type(deck_t), intent(in) :: d
    type(mesh_t), intent(in) :: msh(:)
    type(body_system_t), intent(in) :: sys(:)
    type(result_fields_t), intent(in) :: fields        !< the contact and body fields
    type(interface_t), intent(in) :: itf               !< the normal rows (fields%itf)
    type(faces_t), intent(in) :: surf(:)               !< (npair) the contact surfaces (in space)
    type(contact_result_t), intent(in) :: res          !< the solution on them (fields%last%res)
    real(wp), intent(in) :: u(:, :)
    type(timing_t), intent(in) :: tm
    character(len=*), intent(in) :: run_id
    type(error_t), intent(inout) :: st
    type(step_result_t), intent(in), optional :: steps(:)   !< the load steps (/steps)
    integer(hid_t) :: fid, gid
    integer(haddr_t) :: off(BD_COUNT)
    integer(hsize_t) :: nn, nc
    integer :: a, k, fd
    real(wp), allocatable :: w2(:, :)
    type(error_t), allocatable :: body_err(:)
    type(error_t) :: closing
    character(len=:), allocatable :: ul, us, uf, trib_unit
    character(len=3) :: comp(6)

    comp(1:NSTRESS) = stress_names()
    ul = trim(d%units%length)
    us = trim(d%units%stress)
    uf = trim(d%units%force)//'/'//ul     ! nodal force per unit thickness (2D)
    if (d%axisymmetric) uf = trim(d%units%force)//'/rad'   ! per radian of a body of revolution
    if (NDIM == 3) uf = trim(d%units%force)               ! a solid's nodal force
    trib_unit = tributary_unit(d, ul)
    allocate (body_err(size(msh)))
    fd = -1
    call file_open(path, fid, st, create=.true.)
    if (.not. st%failed()) call data_open(path, fd, st)
    ! root attributes
    call write_attr(fid, 'status', status_name(res%status), st)
    call write_attr(fid, 'method', word(METHOD_CHOICES, res%method), st)
    call write_attr(fid, 'message', trim(res%message), st)
    call write_attr(fid, 'version', program_version, st)
    call write_attr(fid, 'title', trim(d%title), st)
    call write_attr(fid, 'deck', trim(d%source), st)
    call write_attr(fid, 'run_id', run_id, st)
    call write_attr(fid, 'unit_length', ul, st)
    call write_attr(fid, 'unit_force', trim(d%units%force), st)
    ! the plane model; a body of revolution's forces are per radian (its loads, reactions and
    ! contact forces: the whole circumference carries 2 pi times)
    if (NDIM == 2) then
      call write_attr(fid, 'plane', trim(merge('axisymmetric', merge('strain      ', 'stress      ', d%plane_strain), &
                      d%axisymmetric)), st)
      call write_attr(fid, 'forces_per', trim(merge('radian        ', 'unit thickness', d%axisymmetric)), st)
    else
      call write_attr(fid, 'dimension', 3, st)
    end if
    call write_attr(fid, 'unit_stress', us, st)
    call write_attr(fid, 'outer_iterations', res%outer, st)
    call write_attr(fid, 'inner_iterations', res%inner, st)
    call write_attr(fid, 'contact_nodes', itf%m, st)
    call write_attr(fid, 'bodies', size(msh), st)
    call write_attr(fid, 'pairs', itf%npair, st)
    ! which engine wrote the file: the factorization and the number of MPI processes
    call write_attr(fid, 'factorization', trim(word(FACTOR_CHOICES, d%solver%factor%factorization)), st)
    call write_attr(fid, 'ranks', tm%ranks, st)
    call write_attr(fid, 'residual', res%residual, st)
    call write_attr(fid, 'criterion', res%criterion, st)
    call write_attr(fid, 'imbalance', res%imbalance, st)
    call write_attr(fid, 'penetration', res%penetration, st)
    call write_attr(fid, 'complementarity', res%complementarity, st)
    call write_attr(fid, 'equilibrium', res%equilibrium, st)
    call write_attr(fid, 'equality_updates', res%eq_updates, st)
    call write_attr(fid, 'error_bound', res%error_bound, st)
    call write_attr(fid, 'kappa', res%kappa, st)
    call write_attr(fid, 'delta', d%solver%delta, st)
    call write_attr(fid, 'tol', d%solver%tol, st)
    if (allocated(d%effective)) call write_dset(fid, 'input_deck', d%effective, st)
    ! timing
    call group_open(fid, 'timing', gid, st, create=.true.)
    call write_attr(gid, 'assemble_s', tm%assemble, st)
    call write_attr(gid, 'factor_s', tm%factor, st)
    call write_attr(gid, 'condense_s', tm%condense, st)
    call write_attr(gid, 'iterate_s', tm%iterate, st)
    call write_attr(gid, 'output_s', tm%output, st)
    call write_attr(gid, 'total_s', tm%total, st)
    call write_attr(gid, 'peak_rss_mb', tm%peak_rss_mb, st)
    call write_attr(gid, 'factor_mb', tm%factor_mb, st)
    call write_attr(gid, 'factor_tiles', tm%factor_tiles, st)
    call group_close(gid, st)
    ! contact
    call group_open(fid, 'contact', gid, st, create=.true.)
    allocate (w2(itf%m, NDIM))
    w2 = transpose(itf%xy)   ! columns are contiguous: x, y (z)
    call write_dset(gid, 'x', w2(:, 1), st, ul)
    call write_dset(gid, 'y', w2(:, 2), st, ul)
    if (NDIM == 3) call write_dset(gid, 'z', w2(:, 3), st, ul)
    call write_dset(gid, 's', itf%s, st, ul)
    w2 = transpose(row_directions(itf, 1, itf%m))
    call write_dset(gid, 'normal', w2, st, '1')
    w2 = transpose(itf%xy)   ! contiguous (gfortran passes a transpose as a strided view)
    call write_dset(gid, 'coordinates', w2, st, ul)
    deallocate (w2)
    call write_dset(gid, 'g0', itf%g0, st, ul)
    call write_dset(gid, tributary_name(), itf%trib, st, trib_unit)
    call contact_solution(gid, fields%last, ul, us, uf, st)
    ! the contact line as a grid of its own (XDMF): points padded with z = 0, segments (in
    ! space: the contact surfaces' faces)
    call write_dset(gid, 'geometry_xyz', pad3(itf%xy), st, ul)
    call write_contact_cells(gid, contact_cells(itf, surf, 1, itf%npair), st)
    do k = 1, itf%npair
      call write_pair(gid, k, itf, fields%last, ul, us, uf, trib_unit, st, cells=contact_cells(itf, surf, k, k))
    end do
    call group_close(gid, st)
    call write_history(fid, res, st)
    ! bodies
    do a = 1, size(msh)
      call group_open(fid, body_group_name(a), gid, st, create=.true.)
      call write_attr(gid, 'element', trim(element_names(msh(a)%element)), st)
      call write_material(gid, d, a, st)
      call write_attr(gid, 'free_dofs', sys(a)%n, st)
      ! a body held only by contact: its free rigid motions, their amplitudes (the
      ! displacement includes them) and the fixing DOFs of the generalized inverse
      call write_attr(gid, 'free_rigid_motions', sys(a)%nrig, st)
      if (sys(a)%nrig > 0) then
        call write_attr(gid, 'rigid_motions', free_list(sys(a)), st)
        call write_dset(gid, 'rigid_amplitude', res%rigid(1:sys(a)%nrig, a), st, ul)
        call write_dset(gid, 'rigid_basis', sys(a)%rig_coef, st, '1')
        call write_dset(gid, 'fixing_dofs', file_dof(msh(a), sys(a)%fixing) - 1, st, '1')
      end if
      ! the fields: their storage reserved here, their data computed and written by a task
      nn = msh(a)%nnode
      nc = msh(a)%ncell
      off = -1
      call reserve_dset(gid, 'coordinates', [nn, int(NDIM, hsize_t)], .false., off(BD_COORDINATES), st, ul)
      call reserve_dset(gid, 'displacement', [nn, int(NCOMP, hsize_t)], .false., off(BD_DISPLACEMENT), st, ul)
      call reserve_dset(gid, 'geometry_xyz', [3_hsize_t, nn], .false., off(BD_GEOMETRY), st, ul)
      call reserve_dset(gid, 'displacement_xyz', [3_hsize_t, nn], .false., off(BD_DISPLACEMENT_XYZ), st, ul)
      ! 0-based; a triangle of a mixed mesh has -1 as its fourth vertex
      call reserve_dset(gid, 'cells', shape(msh(a)%cells, kind=hsize_t), .true., off(BD_CELLS), st, '1')
      if (msh(a)%element == ELEM_MIXED) call reserve_dset(gid, 'topology', [int(topology_size(msh(a)), hsize_t)], &
        .true., off(BD_TOPOLOGY), st, '1')
      call reserve_dset(gid, 'body_id', [nc], .true., off(BD_BODY_ID), st, '1')
      call reserve_dset(gid, 'stress', [nn, int(NSTRESS, hsize_t)], .false., off(BD_STRESS), st, us)
      ! the components once more, one dataset each (what XDMF readers show as fields)
      do k = 1, NSTRESS
        call reserve_dset(gid, comp(k), [nn], .false., off(BD_SXX + k - 1), st, us)
      end do
      call reserve_dset(gid, 'von_mises', [nn], .false., off(BD_VON_MISES), st, us)
      ! contact pressure as a nodal field of the body (0 off the contact line)
      call reserve_dset(gid, 'contact_pressure', [nn], .false., off(BD_PRESSURE), st, us)
      ! the supports' forces on the body at its nodes (0 off the supports)
      call reserve_dset(gid, 'reaction', [nn, int(NCOMP, hsize_t)], .false., off(BD_REACTION), st, uf)
      call reserve_dset(gid, 'reaction_xyz', [3_hsize_t, nn], .false., off(BD_REACTION_XYZ), st, uf)
      call group_close(gid, st)
      if (.not. st%failed()) then
        !$omp task firstprivate(a, off) shared(msh, u, sys, fields, body_err, fd)
        call body_data(fd, off, a, msh(a), u(1:sys(a)%ndof, a), fields, body_err(a))
        !$omp end task
      end if
    end do
    if (present(steps)) call write_steps(fid, d, msh, sys, fields, steps, ul, us, uf, st)
    call file_close(fid, st)
    ! the bodies' data written (the HDF5 file is closed: no object overlaps their storage)
    !$omp taskwait
    call data_close(fd, closing)
    if (closing%failed() .and. .not. st%failed()) &
      call st%set(ERR_IO, trim(path)//': failed to close the file: '//closing%message)
    ! a body's failure (fields not finite, data not written) first, the bodies in order
    do a = size(msh), 1, -1
      if (body_err(a)%failed()) st = body_err(a)
    end do
  end subroutine write_h5

  !> Body a's fields in the file's node and cell order, each written at its reserved offset
  !! off(BD_*) of the file fd: coordinates and displacement (nnode, 2), both padded with z = 0
  !! (3, nnode), the cells (0-based), for a mixed mesh its XDMF topology, the body id per
  !! cell, and from fields%body_fields the nodal stresses (nnode, 4) and each component, von
  !! Mises and the contact pressure, the supports' reactions (nnode, 2) and padded (3, nnode).
  !! Fields that are not finite are a failure, never written.
  subroutine body_data(fd, off, a, msh, ua, fields, err)
    integer, intent(in) :: fd                       !< the result file (data_open)
    integer(haddr_t), intent(in) :: off(:)          !< (BD_COUNT) where each dataset's data go
    integer, intent(in) :: a                        !< the body
    type(mesh_t), intent(in) :: msh                 !< its mesh
    real(wp), intent(in) :: ua(:)                   !< (ndof) its displacement
    type(result_fields_t), intent(in) :: fields     !< its fields (body_fields)
    type(error_t), intent(inout) :: err             !< the first failure
    real(wp), allocatable, target :: vm(:), w2(:, :), w3(:, :), sigt(:, :), uf(:, :)
    integer, allocatable, target :: iv(:), iw(:, :)
    type(body_fields_t) :: bf
    character(len=3) :: comp(6)
    integer :: k, nn
    comp(1:NSTRESS) = stress_names()
    nn = msh%nnode
    call fields%body_fields(0, a, fields%last%pressure, bf)
    vm = file_order(msh, bf%von_mises)
    if (.not. (all(ieee_is_finite(bf%stress)) .and. all(ieee_is_finite(vm)))) then
      call err%set(ERR_IO, 'the stresses of body '//i2s(a)//' are not finite: beyond double precision, rescale the units')
      return
    end if
    uf = file_order(msh, reshape(ua, [NCOMP, nn]))
    allocate (w3(3, nn))
    w3(1:NDIM, :) = file_order(msh, msh%xy)
    w2 = transpose(w3(1:NDIM, :))
    call put(w2, 'coordinates', BD_COORDINATES)
    w2 = transpose(uf)
    call put(w2, 'displacement', BD_DISPLACEMENT)
    if (NDIM == 2) w3(3, :) = 0.0_wp
    call put(w3, 'geometry_xyz', BD_GEOMETRY)
    w3 = pad3(uf)
    call put(w3, 'displacement_xyz', BD_DISPLACEMENT_XYZ)
    iw = file_cells(msh) - 1
    call put_int(iw, 'cells', BD_CELLS)
    if (msh%element == ELEM_MIXED) then
      iv = mixed_topology(msh)
      call put_int(iv, 'topology', BD_TOPOLOGY)
    end if
    iv = spread(a, 1, msh%ncell)
    call put_int(iv, 'body_id', BD_BODY_ID)
    sigt = transpose(file_order(msh, bf%stress))
    deallocate (bf%stress)       ! each field freed once written: a large body's are large
    call put(sigt, 'stress', BD_STRESS)
    do k = 1, NSTRESS
      call put(sigt(:, k), comp(k), BD_SXX + k - 1)
    end do
    call put(vm, 'von_mises', BD_VON_MISES)
    deallocate (sigt, bf%von_mises)
    vm = file_order(msh, bf%pressure)
    deallocate (bf%pressure)
    call put(vm, 'contact_pressure', BD_PRESSURE)
    uf = file_order(msh, bf%reaction)
    deallocate (bf%reaction)
    w2 = transpose(uf)
    call put(w2, 'reaction', BD_REACTION)
    w3 = pad3(uf)
    call put(w3, 'reaction_xyz', BD_REACTION_XYZ)

  contains

    subroutine put(x, name, k)
      real(wp), intent(in), target, contiguous :: x(..)
      character(len=*), intent(in) :: name
      integer, intent(in) :: k
      call write_data(c_loc(x), int(size(x), c_long_long)*storage_size(x)/8, name, k)
    end subroutine put

    subroutine put_int(x, name, k)
      integer, intent(in), target, contiguous :: x(..)
      character(len=*), intent(in) :: name
      integer, intent(in) :: k
      call write_data(c_loc(x), int(size(x), c_long_long)*storage_size(x)/8, name, k)
    end subroutine put_int

    subroutine write_data(buf, n, name, k)
      use, intrinsic :: iso_c_binding, only: c_ptr
      type(c_ptr), intent(in) :: buf
      integer(c_long_long), intent(in) :: n
      character(len=*), intent(in) :: name
      integer, intent(in) :: k
      type(error_t) :: werr
      if (err%failed()) return
      call data_write(fd, buf, n, int(off(k), c_long_long), werr)
      if (werr%failed()) call err%set(ERR_IO, 'failed to write dataset /body'//i2s(a)//'/'//name//': '//werr%message)
    end subroutine write_data

  end subroutine body_data

  !> The time of a load step in the XDMF time series and /steps: the cumulative load
  !! factor, stage - 1 + its load factor (stage 1 runs over (0, 1], stage 2 over (1, 2]).
  pure real(wp) function step_time(step) result(t)
    type(step_result_t), intent(in) :: step
    t = real(step%stage - 1, wp) + step%load_factor
  end function step_time

  !> /steps/step_<k> for every load step k: its stage, load factor, time, counts and status
  !! (attributes), its contact arrays (contact, contact/pair_<q>) and each body's
  !! displacement and stresses (body<a>), the datasets named as the last result's.
  subroutine write_steps(fid, d, msh, sys, fields, steps, ul, us, uf, st)
    integer(hid_t), intent(in) :: fid
    type(deck_t), intent(in) :: d
    type(mesh_t), intent(in) :: msh(:)
    type(body_system_t), intent(in) :: sys(:)
    type(result_fields_t), intent(in) :: fields   !< the normal rows; the steps' fields (fields%step(k): steps(k))
    type(step_result_t), intent(in) :: steps(:)
    character(len=*), intent(in) :: ul, us, uf
    type(error_t), intent(inout) :: st
    integer(hid_t) :: sid, kid, gid
    integer :: k, a, q, nn, c
    real(wp), allocatable :: sigt(:, :), disp(:, :), rr(:, :)
    type(contact_fields_t) :: cf
    type(body_fields_t) :: bf
    character(len=3) :: comp(6)
    comp(1:NSTRESS) = stress_names()
    call group_open(fid, 'steps', sid, st, create=.true.)
    call write_attr(sid, 'count', size(steps), st)
    call write_attr(sid, 'time', 'cumulative load factor: stage - 1 + load_factor', st)
    do k = 1, size(steps)
      ! one entry per contact node, the tangential part beside it (as the last result)
      call fields%step_contact(k, cf)
      call group_open(sid, 'step_'//i2s(k), kid, st, create=.true.)
      call write_attr(kid, 'stage', steps(k)%stage, st)
      call write_attr(kid, 'load_factor', steps(k)%load_factor, st)
      call write_attr(kid, 'time', step_time(steps(k)), st)
      call write_attr(kid, 'outer', cf%res%outer, st)
      call write_attr(kid, 'inner', cf%res%inner, st)
      call write_attr(kid, 'status', status_name(cf%res%status), st)
      call write_attr(kid, 'residual', cf%res%residual, st)
      if (.not. allocated(cf%res%lam)) then
        call group_close(kid, st)
        cycle
      end if
      call write_attr(kid, 'normal_force_sum', cf%normal_force_sum, st)
      call group_open(kid, 'contact', gid, st, create=.true.)
      call contact_solution(gid, cf, ul, us, uf, st)
      do q = 1, fields%itf%npair
        call write_pair(gid, q, fields%itf, cf, ul, us, uf, tributary_unit(d, ul), st)
      end do
      call group_close(gid, st)
      do a = 1, size(msh)
        nn = msh(a)%nnode
        call group_open(kid, 'body'//i2s(a), gid, st, create=.true.)
        associate (ua => steps(k)%u(1:NCOMP*nn, a))
          disp = transpose(file_order(msh(a), reshape(ua, [NCOMP, nn])))   ! a contiguous copy (see write_h5)
          call write_dset(gid, 'displacement', disp, st, ul)
          call write_dset(gid, 'displacement_xyz', pad3(file_order(msh(a), reshape(ua, [NCOMP, nn]))), st, ul)
        end associate
        call fields%body_fields(k, a, cf%pressure, bf)
        if (.not. (all(ieee_is_finite(bf%stress)) .and. all(ieee_is_finite(bf%von_mises))) .and. .not. st%failed()) &
          call st%set(ERR_IO, 'the stresses of body '//i2s(a)//' in load step '//i2s(k)// &
                      ' are not finite: beyond double precision, rescale the units')
        sigt = transpose(file_order(msh(a), bf%stress))
        call write_dset(gid, 'stress', sigt, st, us)
        do c = 1, NSTRESS
          call write_dset(gid, comp(c), sigt(:, c), st, us)
        end do
        call write_dset(gid, 'von_mises', file_order(msh(a), bf%von_mises), st, us)
        call write_dset(gid, 'contact_pressure', file_order(msh(a), bf%pressure), st, us)
        rr = file_order(msh(a), bf%reaction)
        call write_dset(gid, 'reaction', transpose(rr), st, uf)
        call write_dset(gid, 'reaction_xyz', pad3(rr), st, uf)
        if (sys(a)%nrig > 0) call write_dset(gid, 'rigid_amplitude', cf%res%rigid(1:sys(a)%nrig, a), st, ul)
        call group_close(gid, st)
      end do
      call group_close(kid, st)
    end do
    call group_close(sid, st)

  end subroutine write_steps

  !> The contact solution of all rows into the group gid (/contact, or a load step's):
  !! forces of both sides, their resultant on body 1, pressure, gap, active flags, normal
  !! displacements, obstacles and, with friction, the tangential part.
  subroutine contact_solution(gid, cf, ul, us, uf, st)
    integer(hid_t), intent(in) :: gid
    type(contact_fields_t), intent(in) :: cf    !< the solution's contact fields
    character(len=*), intent(in) :: ul, us, uf  !< units: length, stress, force/length
    type(error_t), intent(inout) :: st
    call write_dset(gid, 'normal_force', cf%res%lam, st, uf)
    call write_dset(gid, 'normal_force_body1', cf%res%lam_body(:, 1), st, uf)
    call write_dset(gid, 'normal_force_body2', cf%res%lam_body(:, 2), st, uf)
    ! the contact forces' resultant on body 1 (x, y): what balances its load
    call write_dset(gid, 'resultant_body1', cf%tg%resultant_all, st, uf)
    call write_dset(gid, 'pressure', cf%pressure, st, us)
    call write_dset(gid, 'gap', cf%res%gap, st, ul)
    call write_dset(gid, 'active', cf%active, st, '1')
    call write_dset(gid, 'normal_displacement_body1', cf%res%w(:, 1), st, ul)
    call write_dset(gid, 'normal_displacement_body2', cf%res%w(:, 2), st, ul)
    call write_dset(gid, 'obstacle_body1', cf%res%obstacle(:, 1), st, ul)
    call write_dset(gid, 'obstacle_body2', cf%res%obstacle(:, 2), st, ul)
    if (cf%tg%on) call write_tangential(gid, cf, 1, size(cf%pressure), ul, us, uf, st)
  end subroutine contact_solution

  !> The group pair_<q> of the contact group gid: pair q's rows alone, its solution (forces
  !! of both sides, the resultant of all its contact forces on its first body, pressure, gap,
  !! active flags, normal displacements, with friction the tangential part) and, given its
  !! `cells` (contact_cells), the ids of its bodies (side 1, side 2), its slave body and its
  !! line (coordinates, normals, g0, tributary lengths, segments or faces 0-based within the
  !! pair).
  subroutine write_pair(gid, q, itf, cf, ul, us, uf, trib_unit, st, cells)
    integer(hid_t), intent(in) :: gid
    integer, intent(in) :: q
    type(interface_t), intent(in) :: itf
    type(contact_fields_t), intent(in) :: cf    !< the solution's contact fields (all rows)
    character(len=*), intent(in) :: ul, us, uf  !< units: length, stress, force/length
    character(len=*), intent(in) :: trib_unit   !< of the tributary lengths (tributary_unit)
    type(error_t), intent(inout) :: st
    integer, intent(in), optional :: cells(:, :)   !< the cells of its grid (absent: its solution alone)
    integer(hid_t) :: pid
    integer :: r(2), i, j
    real(wp), allocatable :: w2(:, :)
    logical :: geo
    geo = present(cells)
    r = pair_rows(itf, q)
    i = r(1)
    j = r(2)
    call group_open(gid, 'pair_'//i2s(q), pid, st, create=.true.)
    if (geo) then
      call write_attr_list(pid, 'bodies', itf%pair_body(:, q), st)
      call write_attr(pid, 'slave_body', itf%pair_body(itf%pair_slave(q), q), st)
      allocate (w2(j - i + 1, NDIM))
      w2 = transpose(itf%xy(:, i:j))
      call write_dset(pid, 'x', w2(:, 1), st, ul)
      call write_dset(pid, 'y', w2(:, 2), st, ul)
      if (NDIM == 3) call write_dset(pid, 'z', w2(:, 3), st, ul)
      call write_dset(pid, 's', itf%s(i:j), st, ul)
      w2 = transpose(row_directions(itf, i, j))
      call write_dset(pid, 'normal', w2, st, '1')
      ! friction in space: the tangents its tangential components are along
      if (NDIM == 3 .and. itf%pair_friction(q) /= FRICTION_NONE) then
        w2 = transpose(itf%frame(:, 2, i:j))
        call write_dset(pid, 'tangent1', w2, st, '1')
        w2 = transpose(itf%frame(:, 3, i:j))
        call write_dset(pid, 'tangent2', w2, st, '1')
      end if
      call write_dset(pid, 'g0', itf%g0(i:j), st, ul)
      call write_dset(pid, tributary_name(), itf%trib(i:j), st, trib_unit)
      call write_dset(pid, 'geometry_xyz', pad3(itf%xy(:, i:j)), st, ul)
      call write_contact_cells(pid, cells, st)
    end if
    call write_dset(pid, 'normal_force', cf%res%lam(i:j), st, uf)
    call write_dset(pid, 'normal_force_side1', cf%res%lam_body(i:j, 1), st, uf)
    call write_dset(pid, 'normal_force_side2', cf%res%lam_body(i:j, 2), st, uf)
    call write_dset(pid, 'resultant_on_first_body', cf%tg%resultant(:, q), st, uf)
    call write_dset(pid, 'pressure', cf%pressure(i:j), st, us)
    call write_dset(pid, 'gap', cf%res%gap(i:j), st, ul)
    call write_dset(pid, 'active', cf%active(i:j), st, '1')
    call write_dset(pid, 'normal_displacement_side1', cf%res%w(i:j, 1), st, ul)
    call write_dset(pid, 'normal_displacement_side2', cf%res%w(i:j, 2), st, ul)
    if (cf%tg%on) then
      if (itf%pair_friction(q) /= FRICTION_NONE) call write_tangential(pid, cf, i, j, ul, us, uf, st)
    end if
    call group_close(pid, st)
  end subroutine write_pair

  !> The tangential part of the nodes i..j (friction) in the group gid (or its subgroup
  !! `sub`): tangential_force, shear, tangential_bound (the bound of |tangential_force|), slip,
  !! slip_increment (the slip of the last load step) and state (0 open, 1 stick, 2 slip,
  !! -1 a node of a frictionless pair; the names in the attribute state_names). In space the
  !! force, shear and slips are (nodes, 2) arrays of their components along the node's
  !! tangents t1, t2 (the pair's `tangent1`, `tangent2`, stored as `normal` is), with the
  !! force also as a vector (tangential_force_xyz, stored as geometry_xyz is) and the shear's
  !! length (shear_magnitude).
  subroutine write_tangential(gid, cf, i, j, ul, us, uf, st, sub)
    integer(hid_t), intent(in) :: gid
    type(contact_fields_t), intent(in) :: cf    !< the solution's contact fields (its tangential part)
    integer, intent(in) :: i, j
    character(len=*), intent(in) :: ul, us, uf
    type(error_t), intent(inout) :: st
    character(len=*), intent(in), optional :: sub
    integer(hid_t) :: pid
    real(wp), allocatable :: a1(:), a2(:, :)
    pid = gid
    if (present(sub)) call group_open(gid, sub, pid, st)
    if (NDIM == 2) then
      a1 = cf%tg%force(1, i:j)
      call write_dset(pid, 'tangential_force', a1, st, uf)
      a1 = cf%tg%shear(1, i:j)
      call write_dset(pid, 'shear', a1, st, us)
      a1 = cf%tg%slip(1, i:j)
      call write_dset(pid, 'slip', a1, st, ul)
      a1 = cf%tg%slip_increment(1, i:j)
      call write_dset(pid, 'slip_increment', a1, st, ul)
    else
      ! (nodes, component) arrays, as `normal`
      a2 = transpose(cf%tg%force(:, i:j))
      call write_dset(pid, 'tangential_force', a2, st, uf)
      ! (x, y, z) per node, as geometry_xyz (ParaView's vector)
      a2 = cf%tg%force_xyz(:, i:j)
      call write_dset(pid, 'tangential_force_xyz', a2, st, uf)
      a2 = transpose(cf%tg%shear(:, i:j))
      call write_dset(pid, 'shear', a2, st, us)
      a1 = cf%shear_magnitude(i:j)
      call write_dset(pid, 'shear_magnitude', a1, st, us)
      a2 = transpose(cf%tg%slip(:, i:j))
      call write_dset(pid, 'slip', a2, st, ul)
      a2 = transpose(cf%tg%slip_increment(:, i:j))
      call write_dset(pid, 'slip_increment', a2, st, ul)
    end if
    call write_dset(pid, 'tangential_bound', cf%tg%bound(i:j), st, uf)
    call write_dset(pid, 'state', cf%tg%state(i:j), st, '1')
    call write_attr(pid, 'state_names', 'none=-1 open=0 stick=1 slip=2', st)
    if (present(sub)) call group_close(pid, st)
  end subroutine write_tangential

  !> The XDMF 'Mixed' topology of a mesh: per cell its type (4 triangle, 5 quadrilateral,
  !! 6 tetrahedron, 9 hexahedron) and its 0-based vertices, in the file's order.
  function mixed_topology(msh) result(t)
    type(mesh_t), intent(in) :: msh
    integer, allocatable :: t(:), cells(:, :), ctype(:)
    integer :: c, k, nv
    allocate (t(topology_size(msh)))
    cells = file_cells(msh)
    ctype = msh%cell_type
    if (allocated(msh%file_cell)) ctype(msh%file_cell) = msh%cell_type
    k = 0
    do c = 1, msh%ncell
      select case (ctype(c))
      case (ELEM_Q1)
        nv = 4
        t(k + 1) = 5
      case (ELEM_P1)
        nv = 3
        t(k + 1) = 4
      case (ELEM_TET4)
        nv = 4
        t(k + 1) = 6
      case default      ! ELEM_HEX8
        nv = 8
        t(k + 1) = 9
      end select
      t(k + 2:k + 1 + nv) = cells(1:nv, c) - 1
      k = k + 1 + nv
    end do
  end function mixed_topology

  !> The length of mixed_topology(msh): per cell its type code and its vertices.
  pure integer function topology_size(msh)
    type(mesh_t), intent(in) :: msh
    topology_size = count(msh%cell_type == ELEM_Q1)*5 + count(msh%cell_type == ELEM_P1)*4 + &
                    count(msh%cell_type == ELEM_TET4)*5 + count(msh%cell_type == ELEM_HEX8)*9
  end function topology_size

  !> Points or vectors (NDIM, n) as (3, n): in the plane padded with z = 0.
  function pad3(v) result(p)
    real(wp), intent(in) :: v(:, :)
    real(wp) :: p(3, size(v, 2))
    p(1:size(v, 1), :) = v
    if (size(v, 1) < 3) p(3, :) = 0.0_wp
  end function pad3

  !> The names of the stress components, in the order of body_fields_t's stress: in the
  !! plane sxx, syy, sxy, szz; in space sxx, syy, szz, syz, sxz, sxy.
  function stress_names() result(c)
    character(len=3), allocatable :: c(:)
    if (NDIM == 3) then
      c = ['sxx', 'syy', 'szz', 'syz', 'sxz', 'sxy']
    else
      c = ['sxx', 'syy', 'sxy', 'szz']
    end if
  end function stress_names

  !> The name of the contact rows' tributary measure D_jj: a length in the plane, an area in
  !! space.
  function tributary_name() result(n)
    character(len=:), allocatable :: n
    n = trim(merge('tributary_length', 'tributary_area  ', NDIM == 2))
  end function tributary_name

  !> The cells of the contact lines of pairs p1..p2 over their n rows (0-based from the
  !! first row of p1, h5py shape (cells, 2)): within each pair the segments (k, k+1) of
  !! neighbouring rows, never one joining two pairs; with no segment at all (each pair
  !! one row or none), and in space, the n rows as vertices (shape (n, 1)).
  function line_cells(itf, p1, p2) result(c)
    type(interface_t), intent(in) :: itf
    integer, intent(in) :: p1, p2              !< first and last pair
    integer, allocatable :: c(:, :)
    integer :: k, q, i0, n, nseg
    i0 = itf%pair_ptr(p1)
    n = itf%pair_ptr(p2 + 1) - i0
    nseg = 0
    do q = p1, p2
      nseg = nseg + max(0, itf%pair_ptr(q + 1) - itf%pair_ptr(q) - 1)
    end do
    if (NDIM == 3) nseg = 0      ! a contact surface without a face (contact_cells): its nodes as vertices
    if (nseg > 0) then
      allocate (c(2, nseg))
      nseg = 0
      do q = p1, p2
        do k = itf%pair_ptr(q), itf%pair_ptr(q + 1) - 2
          nseg = nseg + 1
          c(:, nseg) = [k - i0, k + 1 - i0]
        end do
      end do
    else
      allocate (c(1, n))
      c(1, :) = [(k - 1, k = 1, n)]
    end if
  end function line_cells

  !> The contact surface of each pair in space (surf(q) for pair q; in the plane none): the
  !! faces of the pair's slave group every node of which carries a row of the pair. The
  !! group is the slave side's `&contact` group, or the side of its box declared 'contact'
  !! (as build_interface resolves them). A face with a node that carries no row (not covered
  !! by the master, or removed) is left out.
  subroutine contact_surfaces(d, msh, itf, surf)
    type(deck_t), intent(in) :: d
    type(mesh_t), intent(in) :: msh(:)
    type(interface_t), intent(in) :: itf            !< the normal rows (result_fields_t's itf)
    type(faces_t), allocatable, intent(out) :: surf(:)
    type(contact_cfg_t) :: cc
    integer, allocatable :: rowof(:), f(:, :)
    integer :: q, sl, a, g, e, k, nf, nd
    character(len=:), allocatable :: name
    allocate (surf(itf%npair))
    do q = 1, itf%npair
      allocate (surf(q)%f(4, 0))
      if (NDIM /= 3 .or. q > d%npair) cycle
      sl = itf%pair_slave(q)
      a = itf%pair_body(sl, q)
      cc = pair_oriented(d%pair(q))
      if (len_trim(cc%body_group(1)) == 0) then
        k = findloc(d%body(a)%bc, BC_CONTACT, dim=1)
        if (k == 0) cycle
        name = trim(side_names(k))
      else
        name = trim(cc%body_group(sl))
      end if
      g = group_index(msh(a), name)
      if (g == 0) cycle
      ! each slave node's row, 1-based within the pair (0: none)
      allocate (rowof(msh(a)%nnode))
      rowof = 0
      do k = itf%pair_ptr(q), itf%pair_ptr(q + 1) - 1
        if (itf%node(k, sl) > 0) rowof(itf%node(k, sl)) = k - itf%pair_ptr(q) + 1
      end do
      associate (grp => msh(a)%group(g))
        allocate (f(4, grp%nedge))
        f = -1
        nf = 0
        do e = 1, grp%nedge
          nd = count(grp%edge(:, e) > 0)
          if (nd < 3) cycle
          if (any(rowof(grp%edge(1:nd, e)) == 0)) cycle
          nf = nf + 1
          f(1:nd, nf) = rowof(grp%edge(1:nd, e)) - 1
        end do
        surf(q)%f = f(:, 1:nf)
      end associate
      deallocate (rowof, f)
    end do
  end subroutine contact_surfaces

  !> The cells of the contact grid of pairs p1..p2, 0-based from the first row of p1: in the
  !! plane line_cells; in space the pairs' faces (contact_surfaces), (3, nf) when all are
  !! triangles, else (4, nf) with -1 as a triangle's fourth vertex, and without any face the
  !! rows as vertices (line_cells).
  function contact_cells(itf, surf, p1, p2) result(c)
    type(interface_t), intent(in) :: itf
    type(faces_t), intent(in) :: surf(:)
    integer, intent(in) :: p1, p2              !< first and last pair
    integer, allocatable :: c(:, :)
    integer :: q, nf, k, off
    nf = 0
    if (NDIM == 3) then
      do q = p1, p2
        nf = nf + size(surf(q)%f, 2)
      end do
    end if
    if (nf == 0) then
      c = line_cells(itf, p1, p2)
      return
    end if
    allocate (c(4, nf))
    nf = 0
    do q = p1, p2
      k = size(surf(q)%f, 2)
      off = itf%pair_ptr(q) - itf%pair_ptr(p1)
      c(:, nf + 1:nf + k) = merge(surf(q)%f + off, -1, surf(q)%f >= 0)
      nf = nf + k
    end do
    if (all(c(4, :) < 0)) c = c(1:3, :)
  end function contact_cells

  !> The cells of a contact grid (contact_cells) into the group gid: `segments` (a
  !! polyline's, or its vertices), or a surface's `faces` and, where it mixes triangles and
  !! quadrilaterals, their XDMF `topology` (face_topology).
  subroutine write_contact_cells(gid, c, st)
    integer(hid_t), intent(in) :: gid
    integer, intent(in) :: c(:, :)
    type(error_t), intent(inout) :: st
    integer, allocatable :: w(:, :)
    w = c     ! contiguous, as the writer takes it (a section passed here is not)
    if (size(w, 1) <= 2) then
      call write_dset(gid, 'segments', w, st, '1')
    else
      call write_dset(gid, 'faces', w, st, '1')
      if (any(w < 0)) call write_dset(gid, 'topology', face_topology(w), st, '1')
    end if
  end subroutine write_contact_cells

  !> The XDMF 'Mixed' topology of faces (4, nf) (a triangle's fourth vertex -1): per face its
  !! type (4 triangle, 5 quadrilateral) and its vertices.
  pure function face_topology(c) result(t)
    integer, intent(in) :: c(:, :)
    integer, allocatable :: t(:)
    integer :: e, k, nd
    allocate (t(count(c >= 0) + size(c, 2)))
    k = 0
    do e = 1, size(c, 2)
      nd = count(c(:, e) >= 0)
      t(k + 1) = merge(4, 5, nd == 3)
      t(k + 2:k + 1 + nd) = c(1:nd, e)
      k = k + 1 + nd
    end do
  end function face_topology

  !> An XDMF 3 file, as text, describing the bodies `bodies` and the contact lines `lines`
  !! (0: all rows, /contact, grid 'contact'; k: pair k, /contact/pair_<k>, grid
  !! 'contact_pair<k>') of the HDF5 file `h5`: one uniform grid directly under Domain for
  !! one grid (the layout meshio reads), a spatial collection for several (ParaView). With
  !! load steps (`times`, one per step: the cumulative load factor) a temporal collection
  !! of those, step k's fields from /steps/step_<k> (ParaView's time slider; meshio's
  !! TimeSeriesReader for one grid). A comment names the run that wrote it (the HDF5 file's
  !! attribute run_id).
  function xdmf_text(bodies, lines, h5, msh, itf, surf, run_id, times) result(t)
    integer, intent(in) :: bodies(:), lines(:)
    character(len=*), intent(in) :: h5
    type(mesh_t), intent(in) :: msh(:)
    type(interface_t), intent(in) :: itf
    type(faces_t), intent(in) :: surf(:)     !< the contact surfaces (in space)
    character(len=*), intent(in) :: run_id
    real(wp), intent(in) :: times(:)
    character(len=:), allocatable :: t, h
    character(len=32) :: tv
    type(text_buffer_t) :: b                 ! one block per step: linear in the steps
    integer :: k
    h = xml_escape(h5)
    call b%add(line('<?xml version="1.0" ?>')//line('<!-- robin_contact '//program_version//' run_id '//run_id// &
               ' -->')//line('<Xdmf Version="3.0">')//line('  <Domain>'))
    if (size(times) == 0) then
      call b%add(grids_text(bodies, lines, h, msh, itf, surf, '', ''))
    else
      call b%add(line('    <Grid Name="steps" GridType="Collection" CollectionType="Temporal">'))
      do k = 1, size(times)
        write (tv, '(es24.16)') times(k)
        call b%add(grids_text(bodies, lines, h, msh, itf, surf, '/steps/step_'//i2s(k), trim(adjustl(tv))))
      end do
      call b%add(line('    </Grid>'))
    end if
    call b%add(line('  </Domain>')//line('</Xdmf>'))
    t = b%text()
  end function xdmf_text

  !> The grids of the bodies and contact lines, their fields under the HDF5 group `fields`
  !! ('' : the last result's own groups) and, given `time`, at that time.
  function grids_text(bodies, lines, h, msh, itf, surf, fields, time) result(t)
    integer, intent(in) :: bodies(:), lines(:)
    character(len=*), intent(in) :: h, fields, time
    type(mesh_t), intent(in) :: msh(:)
    type(interface_t), intent(in) :: itf
    type(faces_t), intent(in) :: surf(:)
    character(len=:), allocatable :: t, tt
    type(text_buffer_t) :: b                 ! one grid per body and line: linear in their number
    integer :: k, r(2)
    logical :: many
    many = size(bodies) + size(lines) > 1
    tt = ''
    if (len(time) > 0) tt = line('        <Time Value="'//time//'"/>')
    if (many) then
      call b%add(line('    <Grid Name="bodies" GridType="Collection" CollectionType="Spatial">'))
      call b%add(tt)
      tt = ''
    end if
    do k = 1, size(bodies)
      call b%add(grid_text(bodies(k), h, msh(bodies(k)), fields, tt))
    end do
    do k = 1, size(lines)
      if (lines(k) == 0) then
        call b%add(contact_grid_text('contact', h//':/contact', itf%m, contact_cells(itf, surf, 1, itf%npair), 'body', &
                                     h//':'//fields//'/contact', tt, any(itf%pair_friction /= FRICTION_NONE)))
      else
        r = pair_rows(itf, lines(k))
        call b%add(contact_grid_text('contact_pair'//i2s(lines(k)), h//':/contact/pair_'//i2s(lines(k)), &
                                     r(2) - r(1) + 1, contact_cells(itf, surf, lines(k), lines(k)), 'side', &
                                     h//':'//fields//'/contact/pair_'//i2s(lines(k)), tt, &
                                     itf%pair_friction(lines(k)) /= FRICTION_NONE))
      end if
    end do
    if (many) call b%add(line('    </Grid>'))
    t = b%text()
  end function grids_text

  !> One body as an XDMF uniform grid (topology, XYZ geometry, nodal fields, body id per
  !! cell); h5 is the HDF5 file name, escaped for XML.
  function grid_text(a, h5, msh, fields, time) result(t)
    integer, intent(in) :: a
    character(len=*), intent(in) :: h5
    type(mesh_t), intent(in) :: msh
    character(len=*), intent(in) :: fields   !< the group of the fields ('' : /body<a>'s own)
    character(len=*), intent(in) :: time     !< its <Time> element, or ''
    character(len=:), allocatable :: t, fg
    character(len=16) :: topo
    character(len=64) :: nn, nc, nv
    character(len=:), allocatable :: g
    character(len=3) :: comp(6)
    integer :: k
    comp(1:NSTRESS) = stress_names()
    if (msh%element == ELEM_Q1) then
      topo = 'Quadrilateral'
    else if (msh%element == ELEM_P1) then
      topo = 'Triangle'
    else if (msh%element == ELEM_HEX8) then
      topo = 'Hexahedron'
    else if (msh%element == ELEM_TET4) then
      topo = 'Tetrahedron'
    else
      topo = 'Mixed'
    end if
    write (nn, '(i0)') msh%nnode
    write (nc, '(i0)') msh%ncell
    write (nv, '(i0)') msh%nvert
    g = h5//':/body'//i2s(a)
    fg = h5//':'//fields//'/body'//i2s(a)
    t = line('      <Grid Name="body'//i2s(a)//'" GridType="Uniform">')//time
    t = t//line('        <Topology TopologyType="'//trim(topo)//'" NumberOfElements="'//trim(nc)//'">')
    if (msh%element == ELEM_MIXED) then
      write (nv, '(i0)') topology_size(msh)
      t = t//line('          <DataItem Dimensions="'//trim(nv)// &
                  '" NumberType="Int" Precision="4" Format="HDF">'//g//'/topology</DataItem>')
    else
      t = t//line('          <DataItem Dimensions="'//trim(nc)//' '//trim(nv)// &
                  '" NumberType="Int" Precision="4" Format="HDF">'//g//'/cells</DataItem>')
    end if
    t = t//line('        </Topology>')
    t = t//geometry_text(trim(nn), g//'/geometry_xyz')
    t = t//field_text('displacement', 'Vector', trim(nn)//' 3', fg//'/displacement_xyz')
    t = t//field_text('von_mises', 'Scalar', trim(nn), fg//'/von_mises')
    t = t//field_text('contact_pressure', 'Scalar', trim(nn), fg//'/contact_pressure')
    t = t//field_text('reaction', 'Vector', trim(nn)//' 3', fg//'/reaction_xyz')
    do k = 1, NSTRESS
      t = t//field_text(comp(k), 'Scalar', trim(nn), fg//'/'//comp(k))
    end do
    t = t//field_text('body_id', 'Scalar', trim(nc), g//'/body_id', 'Cell')
    t = t//line('      </Grid>')
  end function grid_text

  !> A contact line as an XDMF uniform grid `name` over the HDF5 group g (file:path): a
  !! polyline over its n nodes (cells: line_cells of its rows; in space a surface of
  !! triangles, quadrilaterals or both, contact_cells) with the contact fields at its
  !! nodes; `side` names the columns of the normal displacements ('body': the
  !! normal_displacement_body1/2 of /contact, 'side': normal_displacement_side1/2 of a pair);
  !! with friction also its shear, tangential force, slip and slip increment (in space the
  !! shear's length, the tangential force as a vector and the node's state).
  function contact_grid_text(name, g, n, cells, side, fg, time, friction) result(t)
    character(len=*), intent(in) :: name, g, side
    character(len=*), intent(in) :: fg     !< file:path of the group of its fields
    character(len=*), intent(in) :: time   !< its <Time> element, or ''
    logical, intent(in) :: friction        !< the line has the tangential datasets
    integer, intent(in) :: n
    integer, intent(in) :: cells(:, :)
    character(len=:), allocatable :: t
    character(len=64) :: nn, nc, nv
    character(len=32) :: f(5)
    character(len=*), parameter :: ft(4) = [character(len=16) :: 'shear', 'tangential_force', 'slip', 'slip_increment']
    integer :: k
    f = [character(len=32) :: 'pressure', 'normal_force', 'gap', 'normal_displacement_', 'normal_displacement_']
    f(4) = trim(f(4))//side//'1'
    f(5) = trim(f(5))//side//'2'
    write (nn, '(i0)') n
    write (nc, '(i0)') size(cells, 2)
    write (nv, '(i0)') size(cells, 1)
    select case (size(cells, 1))
    case (2)
      t = '        <Topology TopologyType="Polyline" NodesPerElement="2" NumberOfElements="'
    case (1)
      t = '        <Topology TopologyType="Polyvertex" NodesPerElement="1" NumberOfElements="'
    case (3)
      t = '        <Topology TopologyType="Triangle" NumberOfElements="'
    case default
      t = '        <Topology TopologyType="'//trim(merge('Mixed        ', 'Quadrilateral', any(cells < 0)))// &
          '" NumberOfElements="'
    end select
    t = line('      <Grid Name="'//name//'" GridType="Uniform">')//time//line(t//trim(nc)//'">')
    if (size(cells, 1) <= 2) then
      t = t//line('          <DataItem Dimensions="'//trim(nc)//' '//trim(nv)// &
                  '" NumberType="Int" Precision="4" Format="HDF">'//g//'/segments</DataItem>')
    else if (any(cells < 0)) then
      write (nv, '(i0)') count(cells >= 0) + size(cells, 2)     ! the length of face_topology(cells)
      t = t//line('          <DataItem Dimensions="'//trim(nv)// &
                  '" NumberType="Int" Precision="4" Format="HDF">'//g//'/topology</DataItem>')
    else
      t = t//line('          <DataItem Dimensions="'//trim(nc)//' '//trim(nv)// &
                  '" NumberType="Int" Precision="4" Format="HDF">'//g//'/faces</DataItem>')
    end if
    t = t//line('        </Topology>')
    t = t//geometry_text(trim(nn), g//'/geometry_xyz')
    do k = 1, size(f)
      t = t//field_text(trim(f(k)), 'Scalar', trim(nn), fg//'/'//trim(f(k)))
    end do
    if (friction .and. NDIM == 2) then
      do k = 1, size(ft)
        t = t//field_text(trim(ft(k)), 'Scalar', trim(nn), fg//'/'//trim(ft(k)))
      end do
    else if (friction) then
      ! in space: the shear's length, the tangential force as a vector, the stick zone
      t = t//field_text('shear_magnitude', 'Scalar', trim(nn), fg//'/shear_magnitude')
      t = t//field_text('tangential_force', 'Vector', trim(nn)//' 3', fg//'/tangential_force_xyz')
      t = t//field_text('state', 'Scalar', trim(nn), fg//'/state', 'Node')
    end if
    t = t//line('      </Grid>')
  end function contact_grid_text

  !> The XYZ geometry of a grid of n points.
  function geometry_text(n, path) result(t)
    character(len=*), intent(in) :: n, path
    character(len=:), allocatable :: t
    t = line('        <Geometry GeometryType="XYZ">')// &
        line('          <DataItem Dimensions="'//n//' 3" NumberType="Float" Precision="8" '// &
             'Format="HDF">'//path//'</DataItem>')// &
        line('        </Geometry>')
  end function geometry_text

  !> A field of a grid: nodal (default), or integer data at `center` ('Cell', or 'Node').
  function field_text(name, kind, dims, path, center) result(t)
    character(len=*), intent(in) :: name, kind, dims, path
    character(len=*), intent(in), optional :: center
    character(len=:), allocatable :: t, c, ty
    c = 'Node'
    ty = 'NumberType="Float" Precision="8"'
    if (present(center)) then
      c = center
      ty = 'NumberType="Int" Precision="4"'
    end if
    t = line('        <Attribute Name="'//name//'" AttributeType="'//kind//'" Center="'//c//'">')// &
        line('          <DataItem Dimensions="'//dims//'" '//ty//' Format="HDF">'//path//'</DataItem>')// &
        line('        </Attribute>')
  end function field_text

  !> s with the XML special characters & < > " ' replaced by entities.
  pure function xml_escape(s) result(t)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: t
    integer :: i
    t = ''
    do i = 1, len(s)
      select case (s(i:i))
      case ('&')
        t = t//'&amp;'
      case ('<')
        t = t//'&lt;'
      case ('>')
        t = t//'&gt;'
      case ('"')
        t = t//'&quot;'
      case ("'")
        t = t//'&apos;'
      case default
        t = t//s(i:i)
      end select
    end do
  end function xml_escape

  pure function line(s) result(t)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: t
    t = s//achar(10)
  end function line

  !> A body's material attributes: young, poisson, density of its isotropic material (its own
  !! or a &material's); with a &material its name and angle too; with regions their names.
  subroutine write_material(gid, d, a, st)
    integer(hid_t), intent(in) :: gid
    type(deck_t), intent(in) :: d
    integer, intent(in) :: a
    type(error_t), intent(inout) :: st
    integer :: k, i
    character(len=:), allocatable :: names
    if (len_trim(d%body(a)%material) == 0) then
      call write_attr(gid, 'young', d%body(a)%young, st)
      call write_attr(gid, 'density', d%body(a)%density, st)
      call write_attr(gid, 'poisson', d%body(a)%poisson, st)
    else
      call write_attr(gid, 'material', trim(d%body(a)%material), st)
      call write_attr(gid, 'angle', d%body(a)%angle, st)
      do k = 1, d%nmaterial
        if (d%material(k)%name /= d%body(a)%material) cycle
        call write_attr(gid, 'density', d%material(k)%density, st)
        if (d%material(k)%kind /= MAT_ISOTROPIC) cycle
        call write_attr(gid, 'young', d%material(k)%young, st)
        call write_attr(gid, 'poisson', d%material(k)%poisson, st)
      end do
    end if
    names = ''
    do i = 1, d%nregion
      if (d%region(i)%body == a) names = names//merge(', ', '  ', len(names) > 0)//trim(d%region(i)%name)// &
                                         ' ('//trim(d%region(i)%material)//')'
    end do
    if (len(names) > 0) call write_attr(gid, 'regions', trim(adjustl(names)), st)
  end subroutine write_material

  !> The unit of the tributary lengths D_jj: a length, or for bodies of revolution int N r ds,
  !! an area per radian.
  function tributary_unit(d, ul) result(u)
    type(deck_t), intent(in) :: d
    character(len=*), intent(in) :: ul     !< the length unit
    character(len=:), allocatable :: u
    u = ul
    if (d%axisymmetric) u = ul//'^2/rad'
    if (NDIM == 3) u = ul//'^2'
  end function tributary_unit

end module results
