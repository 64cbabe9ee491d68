!> Result files: one HDF5 file per run, written whole or not at all (temporary
!! name in the same folder, then rename), and an XDMF 3 file beside it so that
!! ParaView opens both bodies directly.
module results
  use kinds, only: wp
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  use hdf5, only: hid_t, h5open_f, h5fcreate_f, h5fclose_f, h5gcreate_f, h5gclose_f, H5F_ACC_TRUNC_F
  use h5io, only: dset_r1, dset_r2, dset_i1, dset_i2, dset_str, attr_str, attr_int, attr_real
  use config, only: deck_t, ELEM_Q1, element_names
  use mesh, only: mesh_t
  use assembly, only: body_system_t, expand, nodal_stress
  use condense, only: interface_t, body_condensed_t
  use contact_types, only: contact_result_t
  implicit none
  private

  character(len=*), parameter, public :: program_version = '1.0.0'  !< robin_contact version

  !> Wall-time breakdown of a run [s] and memory.
  type, public :: timing_t
    real(wp) :: assemble = 0.0_wp
    real(wp) :: factor = 0.0_wp
    real(wp) :: condense = 0.0_wp
    real(wp) :: iterate = 0.0_wp
    real(wp) :: output = 0.0_wp
    real(wp) :: total = 0.0_wp
    real(wp) :: peak_rss_mb = 0.0_wp          !< peak resident memory [MiB]
    real(wp) :: factor_mb = 0.0_wp            !< memory of the two Cholesky factors [MiB]
  end type timing_t

  public :: write_results, write_history, ensure_parent_dir, atomic_rename

  interface
    integer(c_int) function c_rename(old, new) bind(c, name='rename')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_rename
    integer(c_int) function c_mkdir(path, mode) bind(c, name='mkdir')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
    end function c_mkdir
    integer(c_int) function c_unlink(path) bind(c, name='unlink')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function c_unlink
  end interface

contains

  !> Create the folders leading to `file` (like mkdir -p of its parent).
  subroutine ensure_parent_dir(file)
    character(len=*), intent(in) :: file  !< a file path
    integer :: i, rc
    do i = 2, len_trim(file)
      if (file(i:i) == '/') rc = c_mkdir(file(1:i - 1)//c_null_char, int(o'755', c_int))
    end do
  end subroutine ensure_parent_dir

  !> rename(2): atomic within one file system. ok = .false. on failure.
  subroutine atomic_rename(old, new, ok)
    character(len=*), intent(in) :: old   !< temporary name
    character(len=*), intent(in) :: new   !< final name
    logical, intent(out) :: ok            !< success
    ok = c_rename(trim(old)//c_null_char, trim(new)//c_null_char) == 0
  end subroutine atomic_rename

  !> Write the HDF5 result and its XDMF companion. ok = .false. and msg on failure;
  !! no partial file is left behind.
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
    character(len=:), allocatable :: tmp, xdmf
    character(len=600) :: bx(2), bt(2)
    integer(hid_t) :: fid, gid
    integer :: err, a, rc, k, i
    real(wp), allocatable :: sig(:, :), vm(:), pres(:), w2(:, :), w3(:, :), ua(:), sigt(:, :)
    character(len=8) :: bname
    logical :: okx

    ok = .false.
    msg = ''
    call ensure_parent_dir(file)
    tmp = trim(file)//'.tmp'
    call h5open_f(err)
    if (err /= 0) then
      msg = 'cannot initialise HDF5'
      return
    end if
    call h5fcreate_f(tmp, H5F_ACC_TRUNC_F, fid, err)
    if (err /= 0) then
      msg = 'cannot create '//tmp
      return
    end if
    ! root attributes
    call attr_str(fid, 'status', trim(res%status))
    call attr_str(fid, 'method', trim(res%method))
    call attr_str(fid, 'message', trim(res%message))
    call attr_str(fid, 'version', program_version)
    call attr_str(fid, 'title', trim(d%title))
    call attr_str(fid, 'deck', trim(d%source))
    call attr_int(fid, 'outer_iterations', res%outer)
    call attr_int(fid, 'inner_iterations', res%inner)
    call attr_int(fid, 'contact_nodes', itf%m)
    call attr_real(fid, 'residual', res%residual)
    call attr_real(fid, 'criterion', res%criterion)
    call attr_real(fid, 'imbalance', res%imbalance)
    call attr_real(fid, 'penetration', res%penetration)
    call attr_real(fid, 'complementarity', res%complementarity)
    call attr_real(fid, 'error_bound', res%error_bound)
    call attr_real(fid, 'kappa', res%kappa)
    call attr_real(fid, 'delta', d%solver%delta)
    call attr_real(fid, 'tol', d%solver%tol)
    if (allocated(d%effective)) call dset_str(fid, 'input_deck', d%effective)
    ! timing
    call h5gcreate_f(fid, 'timing', gid, err)
    call attr_real(gid, 'assemble_s', tm%assemble)
    call attr_real(gid, 'factor_s', tm%factor)
    call attr_real(gid, 'condense_s', tm%condense)
    call attr_real(gid, 'iterate_s', tm%iterate)
    call attr_real(gid, 'output_s', tm%output)
    call attr_real(gid, 'total_s', tm%total)
    call attr_real(gid, 'peak_rss_mb', tm%peak_rss_mb)
    call attr_real(gid, 'factor_mb', tm%factor_mb)
    call h5gclose_f(gid, err)
    ! contact
    call h5gcreate_f(fid, 'contact', gid, err)
    call dset_r1(gid, 'x', itf%s)
    allocate (w2(itf%m, 2))
    w2 = transpose(itf%xy)
    call dset_r2(gid, 'coordinates', w2)
    deallocate (w2)
    call dset_r1(gid, 'g0', itf%g0)
    call dset_r1(gid, 'tributary_length', itf%trib)
    call dset_r1(gid, 'normal_force', res%lam)
    call dset_r1(gid, 'normal_force_body1', res%lam_body(:, 1))
    call dset_r1(gid, 'normal_force_body2', res%lam_body(:, 2))
    allocate (pres(itf%m))
    where (itf%trib > 0.0_wp)
      pres = res%lam/itf%trib
    elsewhere
      pres = 0.0_wp
    end where
    call dset_r1(gid, 'pressure', pres)
    call dset_r1(gid, 'gap', res%gap)
    call dset_i1(gid, 'active', merge(1, 0, res%lam > 0.0_wp))
    call dset_r1(gid, 'normal_displacement_body1', res%w(:, 1))
    call dset_r1(gid, 'normal_displacement_body2', res%w(:, 2))
    call dset_r1(gid, 'obstacle_body1', res%obstacle(:, 1))
    call dset_r1(gid, 'obstacle_body2', res%obstacle(:, 2))
    call h5gclose_f(gid, err)
    call write_history(fid, res)
    ! bodies
    do a = 1, 2
      write (bname, '(a,i0)') 'body', a
      call h5gcreate_f(fid, trim(bname), gid, err)
      call attr_str(gid, 'element', element_names(msh(a)%element))
      call attr_real(gid, 'young', d%body(a)%young)
      call attr_real(gid, 'poisson', d%body(a)%poisson)
      call attr_int(gid, 'free_dofs', sys(a)%n)
      ! (nnode, 2) in Fortran order -> h5py shape (2, nnode)
      allocate (w2(msh(a)%nnode, 2), w3(3, msh(a)%nnode), ua(sys(a)%ndof))
      ua = u(1:sys(a)%ndof, a)
      w2 = transpose(msh(a)%xy)
      call dset_r2(gid, 'coordinates', w2)
      w2 = transpose(reshape(ua, [2, msh(a)%nnode]))
      call dset_r2(gid, 'displacement', w2)
      w3 = pad3(msh(a)%xy)
      call dset_r2(gid, 'geometry_xyz', w3)
      w3 = pad3(reshape(ua, [2, msh(a)%nnode]))
      call dset_r2(gid, 'displacement_xyz', w3)
      call dset_i2(gid, 'cells', msh(a)%cells - 1)
      allocate (sig(4, msh(a)%nnode), vm(msh(a)%nnode), sigt(msh(a)%nnode, 4))
      call nodal_stress(msh(a), d%body(a), d%plane_strain, ua, sig, vm)
      sigt = transpose(sig)
      call dset_r2(gid, 'stress', sigt)
      deallocate (w2, w3, ua, sigt)
      call dset_r1(gid, 'von_mises', vm)
      ! contact pressure as a nodal field of the body (0 off the contact line)
      deallocate (vm)
      allocate (vm(msh(a)%nnode))
      vm = 0.0_wp
      do k = 1, itf%m
        i = itf%node(k, a)
        vm(i) = pres(k)
      end do
      call dset_r1(gid, 'contact_pressure', vm)
      deallocate (sig, vm)
      call h5gclose_f(gid, err)
    end do
    call h5fclose_f(fid, err)
    if (err /= 0) then
      msg = 'cannot close '//tmp
      rc = c_unlink(tmp//c_null_char)
      return
    end if
    ! XDMF companions, also written under temporary names
    xdmf = xdmf_name(file, '.xdmf')
    bx(1) = xdmf_name(file, '_body1.xdmf')
    bx(2) = xdmf_name(file, '_body2.xdmf')
    bt(1) = trim(bx(1))//'.tmp'
    bt(2) = trim(bx(2))//'.tmp'
    call write_xdmf(xdmf//'.tmp', bt, base_name(file), msh, okx)
    if (.not. okx) then
      msg = 'cannot write '//xdmf
      call remove_files()
      return
    end if
    call atomic_rename(tmp, file, ok)
    if (.not. ok) then
      msg = 'cannot rename '//tmp//' to '//trim(file)
      call remove_files()
      return
    end if
    call atomic_rename(xdmf//'.tmp', xdmf, ok)
    if (ok) call atomic_rename(trim(bx(1))//'.tmp', trim(bx(1)), ok)
    if (ok) call atomic_rename(trim(bx(2))//'.tmp', trim(bx(2)), ok)
    if (.not. ok) msg = 'cannot rename the XDMF files beside '//trim(file)

  contains

    subroutine remove_files()
      rc = c_unlink(tmp//c_null_char)
      rc = c_unlink(xdmf//'.tmp'//c_null_char)
      rc = c_unlink(trim(bx(1))//'.tmp'//c_null_char)
      rc = c_unlink(trim(bx(2))//'.tmp'//c_null_char)
    end subroutine remove_files

  end subroutine write_results

  !> The group /history of an open HDF5 file: one entry per outer iteration.
  subroutine write_history(fid, res)
    integer(hid_t), intent(in) :: fid              !< open file
    type(contact_result_t), intent(in) :: res      !< history source
    integer(hid_t) :: gid
    integer :: err
    call h5gcreate_f(fid, 'history', gid, err)
    call dset_r1(gid, 'criterion', res%h_criterion(1:res%nhist))
    call dset_r1(gid, 'residual', res%h_residual(1:res%nhist))
    call dset_i1(gid, 'inner', res%h_inner(1:res%nhist))
    call dset_i1(gid, 'active', res%h_active(1:res%nhist))
    call dset_r1(gid, 'wall_s', res%h_wall(1:res%nhist))
    call h5gclose_f(gid, err)
  end subroutine write_history

  function pad3(v) result(p)
    real(wp), intent(in) :: v(:, :)
    real(wp) :: p(3, size(v, 2))
    p(1:2, :) = v
    p(3, :) = 0.0_wp
  end function pad3

  !> The result path with its .h5 suffix replaced by `suffix`.
  function xdmf_name(file, suffix) result(x)
    character(len=*), intent(in) :: file, suffix
    character(len=:), allocatable :: x
    integer :: l
    l = len_trim(file)
    if (l > 3) then
      if (file(l - 2:l) == '.h5') then
        x = file(1:l - 3)//suffix
        return
      end if
    end if
    x = trim(file)//suffix
  end function xdmf_name

  function base_name(file) result(b)
    character(len=*), intent(in) :: file
    character(len=:), allocatable :: b
    integer :: i
    i = index(trim(file), '/', back=.true.)
    b = trim(file(i + 1:))
  end function base_name

  !> The XDMF files: `path` holds both bodies as a spatial collection (ParaView);
  !! `bpath(a)` one body each (readers that take a single grid, such as meshio).
  subroutine write_xdmf(path, bpath, h5, msh, ok)
    character(len=*), intent(in) :: path, bpath(2), h5
    type(mesh_t), intent(in) :: msh(2)
    logical, intent(out) :: ok
    integer :: u, a, ios
    open (newunit=u, file=path, status='replace', action='write', iostat=ios)
    ok = ios == 0
    if (.not. ok) return
    write (u, '(a)') '<?xml version="1.0" ?>'
    write (u, '(a)') '<Xdmf Version="3.0">'
    write (u, '(a)') '  <Domain>'
    write (u, '(a)') '    <Grid Name="bodies" GridType="Collection" CollectionType="Spatial">'
    do a = 1, 2
      call write_grid(u, a, h5, msh(a))
    end do
    write (u, '(a)') '    </Grid>'
    write (u, '(a)') '  </Domain>'
    write (u, '(a)') '</Xdmf>'
    close (u, iostat=ios)
    ok = ios == 0
    do a = 1, 2
      if (.not. ok) return
      open (newunit=u, file=bpath(a), status='replace', action='write', iostat=ios)
      ok = ios == 0
      if (.not. ok) return
      write (u, '(a)') '<?xml version="1.0" ?>'
      write (u, '(a)') '<Xdmf Version="3.0">'
      write (u, '(a)') '  <Domain>'
      call write_grid(u, a, h5, msh(a))
      write (u, '(a)') '  </Domain>'
      write (u, '(a)') '</Xdmf>'
      close (u, iostat=ios)
      ok = ios == 0
    end do
  end subroutine write_xdmf

  !> One body as an XDMF uniform grid (topology, XYZ geometry, nodal fields).
  subroutine write_grid(u, a, h5, msh)
    integer, intent(in) :: u, a
    character(len=*), intent(in) :: h5
    type(mesh_t), intent(in) :: msh
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
    write (u, '(a,i0,a)') '      <Grid Name="body', a, '" GridType="Uniform">'
    write (u, '(a)') '        <Topology TopologyType="'//trim(topo)//'" NumberOfElements="'//trim(nc)//'">'
    write (u, '(a)') '          <DataItem Dimensions="'//trim(nc)//' '//trim(nv)// &
      '" NumberType="Int" Precision="4" Format="HDF">'//g//'/cells</DataItem>'
    write (u, '(a)') '        </Topology>'
    write (u, '(a)') '        <Geometry GeometryType="XYZ">'
    write (u, '(a)') '          <DataItem Dimensions="'//trim(nn)//' 3" NumberType="Float" Precision="8" '// &
      'Format="HDF">'//g//'/geometry_xyz</DataItem>'
    write (u, '(a)') '        </Geometry>'
    call xattr(u, 'displacement', 'Vector', trim(nn)//' 3', g//'/displacement_xyz')
    call xattr(u, 'von_mises', 'Scalar', trim(nn), g//'/von_mises')
    call xattr(u, 'contact_pressure', 'Scalar', trim(nn), g//'/contact_pressure')
    write (u, '(a)') '      </Grid>'
  end subroutine write_grid

  subroutine xattr(u, name, kind, dims, path)
    integer, intent(in) :: u
    character(len=*), intent(in) :: name, kind, dims, path
    write (u, '(a)') '        <Attribute Name="'//name//'" AttributeType="'//kind//'" Center="Node">'
    write (u, '(a)') '          <DataItem Dimensions="'//dims//'" NumberType="Float" Precision="8" '// &
      'Format="HDF">'//path//'</DataItem>'
    write (u, '(a)') '        </Attribute>'
  end subroutine xattr

end module results
