!> Result files: one HDF5 file per run, written whole or not at all (temporary
!! name in the same folder, then rename), and an XDMF 3 file beside it so that
!! ParaView opens both bodies directly.
module results
  use kinds, only: wp
  use hdf5, only: hid_t
  use h5io, only: h5_status_t, file_open, file_close, group_open, group_close, write_dset, write_attr
  use history_io, only: write_history
  use files, only: temp_name, replace_suffix, base_name, ensure_parent_dir, atomic_rename, remove_file, &
                   write_text
  use config, only: deck_t, ELEM_Q1, element_names
  use mesh, only: mesh_t
  use assembly, only: body_system_t, nodal_stress
  use condense, only: interface_t
  use contact_types, only: contact_result_t
  implicit none (type, external)
  private

  character(len=*), parameter, public :: program_version = '1.0.0'  !< robin_contact version

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
  end type timing_t

  public :: write_results, remove_results

contains

  !> Write the HDF5 result and its XDMF companions, each under a temporary name first and
  !! renamed only when all are complete. ok = .false. and msg (naming the file and what
  !! failed) otherwise; then no file is left under a result name nor a temporary one.
  subroutine write_results(file, d, msh, sys, itf, res, u, tm, ok, msg)
    character(len=*), intent(in) :: file               !< result path (.h5)
    type(deck_t), intent(in) :: d                      !< the effective deck
    type(mesh_t), intent(in) :: msh(2)                 !< meshes
    type(body_system_t), intent(in) :: sys(2)          !< systems (DOF maps)
    type(interface_t), intent(in) :: itf               !< contact line
    type(contact_result_t), intent(in) :: res          !< contact solution
    real(wp), intent(in) :: u(:, :)                    !< (maxndof, 2) full displacements
    type(timing_t), intent(in) :: tm                   !< timing breakdown
    logical, intent(out) :: ok                         !< success
    character(len=*), intent(out) :: msg               !< failure description
    character(len=len_trim(file) + 16) :: name(4)
    type(h5_status_t) :: st
    integer :: k, a

    ok = .false.
    msg = ''
    call ensure_parent_dir(file)
    call result_files(file, name)
    call write_h5(temp_name(name(1)), d, msh, sys, itf, res, u, tm, st)
    if (st%failed) then
      msg = 'cannot write '//trim(file)//' ('//st%what//')'
      call remove_all(.false.)
      return
    end if
    ! the XDMF files: both bodies (ParaView), then one body each (meshio)
    call write_text(temp_name(name(2)), xdmf_text([1, 2], base_name(file), msh), ok)
    do a = 1, 2
      if (ok) call write_text(temp_name(name(2 + a)), xdmf_text([a], base_name(file), msh), ok)
    end do
    if (.not. ok) then
      msg = 'cannot write the XDMF files beside '//trim(file)
      call remove_all(.false.)
      return
    end if
    ! companions first, the HDF5 file last: it appears only with its XDMF files
    do k = size(name), 1, -1
      call atomic_rename(temp_name(name(k)), name(k), ok)
      if (.not. ok) then
        msg = 'cannot rename '//temp_name(name(k))//' to '//trim(name(k))
        call remove_all(.true.)
        return
      end if
    end do

  contains

    subroutine remove_all(finals)
      logical, intent(in) :: finals   ! also the final names (some renames were done)
      integer :: j
      do j = 1, size(name)
        call remove_file(temp_name(name(j)))
        if (finals) call remove_file(name(j))
      end do
    end subroutine remove_all

  end subroutine write_results

  !> Remove the files of a result (the HDF5 file and its XDMF companions), so that a run
  !! that ends before writing leaves none of an earlier run's behind.
  subroutine remove_results(file)
    character(len=*), intent(in) :: file   !< result path (.h5)
    character(len=len_trim(file) + 16) :: name(4)
    integer :: k
    call result_files(file, name)
    do k = 1, size(name)
      call remove_file(name(k))
    end do
  end subroutine remove_results

  !> The files of a result: the HDF5 file, <stem>.xdmf, <stem>_body1.xdmf, <stem>_body2.xdmf.
  subroutine result_files(file, name)
    character(len=*), intent(in) :: file
    character(len=*), intent(out) :: name(4)
    name(1) = file
    name(2) = replace_suffix(file, '.h5', '.xdmf')
    name(3) = replace_suffix(file, '.h5', '_body1.xdmf')
    name(4) = replace_suffix(file, '.h5', '_body2.xdmf')
  end subroutine result_files

  !> The HDF5 result file `path`, whole; st records the first failure.
  subroutine write_h5(path, d, msh, sys, itf, res, u, tm, st)
    character(len=*), intent(in) :: path
    type(deck_t), intent(in) :: d
    type(mesh_t), intent(in) :: msh(2)
    type(body_system_t), intent(in) :: sys(2)
    type(interface_t), intent(in) :: itf
    type(contact_result_t), intent(in) :: res
    real(wp), intent(in) :: u(:, :)
    type(timing_t), intent(in) :: tm
    type(h5_status_t), intent(inout) :: st
    integer(hid_t) :: fid, gid
    integer :: a, k, i
    real(wp), allocatable :: sig(:, :), vm(:), pres(:), w2(:, :), w3(:, :), ua(:), sigt(:, :)
    character(len=8) :: bname

    call file_open(path, fid, st, create=.true.)
    ! root attributes
    call write_attr(fid, 'status', trim(res%status), st)
    call write_attr(fid, 'method', trim(res%method), st)
    call write_attr(fid, 'message', trim(res%message), st)
    call write_attr(fid, 'version', program_version, st)
    call write_attr(fid, 'title', trim(d%title), st)
    call write_attr(fid, 'deck', trim(d%source), st)
    call write_attr(fid, 'outer_iterations', res%outer, st)
    call write_attr(fid, 'inner_iterations', res%inner, st)
    call write_attr(fid, 'contact_nodes', itf%m, st)
    call write_attr(fid, 'residual', res%residual, st)
    call write_attr(fid, 'criterion', res%criterion, st)
    call write_attr(fid, 'imbalance', res%imbalance, st)
    call write_attr(fid, 'penetration', res%penetration, st)
    call write_attr(fid, 'complementarity', res%complementarity, st)
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
    call group_close(gid, st)
    ! contact
    call group_open(fid, 'contact', gid, st, create=.true.)
    call write_dset(gid, 'x', itf%s, st)
    call write_dset(gid, 'coordinates', transpose(itf%xy), st)
    call write_dset(gid, 'g0', itf%g0, st)
    call write_dset(gid, 'tributary_length', itf%trib, st)
    call write_dset(gid, 'normal_force', res%lam, st)
    call write_dset(gid, 'normal_force_body1', res%lam_body(:, 1), st)
    call write_dset(gid, 'normal_force_body2', res%lam_body(:, 2), st)
    allocate (pres(itf%m))
    where (itf%trib > 0.0_wp)
      pres = res%lam/itf%trib
    elsewhere
      pres = 0.0_wp
    end where
    call write_dset(gid, 'pressure', pres, st)
    call write_dset(gid, 'gap', res%gap, st)
    call write_dset(gid, 'active', merge(1, 0, res%lam > 0.0_wp), st)
    call write_dset(gid, 'normal_displacement_body1', res%w(:, 1), st)
    call write_dset(gid, 'normal_displacement_body2', res%w(:, 2), st)
    call write_dset(gid, 'obstacle_body1', res%obstacle(:, 1), st)
    call write_dset(gid, 'obstacle_body2', res%obstacle(:, 2), st)
    call group_close(gid, st)
    call write_history(fid, res, st)
    ! bodies
    do a = 1, 2
      write (bname, '(a,i0)') 'body', a
      call group_open(fid, trim(bname), gid, st, create=.true.)
      call write_attr(gid, 'element', element_names(msh(a)%element), st)
      call write_attr(gid, 'young', d%body(a)%young, st)
      call write_attr(gid, 'poisson', d%body(a)%poisson, st)
      call write_attr(gid, 'free_dofs', sys(a)%n, st)
      ! (nnode, 2) in Fortran order -> h5py shape (2, nnode)
      allocate (w2(msh(a)%nnode, 2), w3(3, msh(a)%nnode), ua(sys(a)%ndof))
      ua = u(1:sys(a)%ndof, a)
      w2 = transpose(msh(a)%xy)
      call write_dset(gid, 'coordinates', w2, st)
      w2 = transpose(reshape(ua, [2, msh(a)%nnode]))
      call write_dset(gid, 'displacement', w2, st)
      w3 = pad3(msh(a)%xy)
      call write_dset(gid, 'geometry_xyz', w3, st)
      w3 = pad3(reshape(ua, [2, msh(a)%nnode]))
      call write_dset(gid, 'displacement_xyz', w3, st)
      call write_dset(gid, 'cells', msh(a)%cells - 1, st)
      allocate (sig(4, msh(a)%nnode), vm(msh(a)%nnode), sigt(msh(a)%nnode, 4))
      call nodal_stress(msh(a), d%body(a), d%plane_strain, ua, sig, vm)
      sigt = transpose(sig)
      call write_dset(gid, 'stress', sigt, st)
      call write_dset(gid, 'von_mises', vm, st)
      ! contact pressure as a nodal field of the body (0 off the contact line)
      vm = 0.0_wp
      do k = 1, itf%m
        i = itf%node(k, a)
        vm(i) = pres(k)
      end do
      call write_dset(gid, 'contact_pressure', vm, st)
      deallocate (w2, w3, ua, sigt, sig, vm)
      call group_close(gid, st)
    end do
    call file_close(fid, st)
  end subroutine write_h5

  function pad3(v) result(p)
    real(wp), intent(in) :: v(:, :)
    real(wp) :: p(3, size(v, 2))
    p(1:2, :) = v
    p(3, :) = 0.0_wp
  end function pad3

  !> An XDMF 3 file, as text, describing the bodies `bodies` of the HDF5 file `h5`: one
  !! uniform grid directly under Domain for one body (the layout meshio reads), a spatial
  !! collection for both (ParaView).
  function xdmf_text(bodies, h5, msh) result(t)
    integer, intent(in) :: bodies(:)
    character(len=*), intent(in) :: h5
    type(mesh_t), intent(in) :: msh(2)
    character(len=:), allocatable :: t
    integer :: k
    t = line('<?xml version="1.0" ?>')//line('<Xdmf Version="3.0">')//line('  <Domain>')
    if (size(bodies) > 1) t = t//line('    <Grid Name="bodies" GridType="Collection" CollectionType="Spatial">')
    do k = 1, size(bodies)
      t = t//grid_text(bodies(k), h5, msh(bodies(k)))
    end do
    if (size(bodies) > 1) t = t//line('    </Grid>')
    t = t//line('  </Domain>')//line('</Xdmf>')
  end function xdmf_text

  !> One body as an XDMF uniform grid (topology, XYZ geometry, nodal fields).
  function grid_text(a, h5, msh) result(t)
    integer, intent(in) :: a
    character(len=*), intent(in) :: h5
    type(mesh_t), intent(in) :: msh
    character(len=:), allocatable :: t
    character(len=16) :: topo
    character(len=64) :: nn, nc, nv
    character(len=:), allocatable :: g
    if (msh%element == ELEM_Q1) then
      topo = 'Quadrilateral'
    else
      topo = 'Triangle'
    end if
    write (nn, '(i0)') msh%nnode
    write (nc, '(i0)') msh%ncell
    write (nv, '(i0)') msh%nvert
    g = h5//':/body'//achar(48 + a)
    t = line('      <Grid Name="body'//achar(48 + a)//'" GridType="Uniform">')
    t = t//line('        <Topology TopologyType="'//trim(topo)//'" NumberOfElements="'//trim(nc)//'">')
    t = t//line('          <DataItem Dimensions="'//trim(nc)//' '//trim(nv)// &
                '" NumberType="Int" Precision="4" Format="HDF">'//g//'/cells</DataItem>')
    t = t//line('        </Topology>')
    t = t//line('        <Geometry GeometryType="XYZ">')
    t = t//line('          <DataItem Dimensions="'//trim(nn)//' 3" NumberType="Float" Precision="8" '// &
                'Format="HDF">'//g//'/geometry_xyz</DataItem>')
    t = t//line('        </Geometry>')
    t = t//field_text('displacement', 'Vector', trim(nn)//' 3', g//'/displacement_xyz')
    t = t//field_text('von_mises', 'Scalar', trim(nn), g//'/von_mises')
    t = t//field_text('contact_pressure', 'Scalar', trim(nn), g//'/contact_pressure')
    t = t//line('      </Grid>')
  end function grid_text

  !> A nodal field of a grid.
  function field_text(name, kind, dims, path) result(t)
    character(len=*), intent(in) :: name, kind, dims, path
    character(len=:), allocatable :: t
    t = line('        <Attribute Name="'//name//'" AttributeType="'//kind//'" Center="Node">')// &
        line('          <DataItem Dimensions="'//dims//'" NumberType="Float" Precision="8" '// &
             'Format="HDF">'//path//'</DataItem>')// &
        line('        </Attribute>')
  end function field_text

  pure function line(s) result(t)
    character(len=*), intent(in) :: s
    character(len=:), allocatable :: t
    t = s//achar(10)
  end function line

end module results
