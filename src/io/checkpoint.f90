!> Checkpoint and restart of the outer Robin iteration: the whole outer state
!! (obstacles, contact forces, acceleration history, counters) and the history so
!! far, written atomically to `<result file>.ckpt.h5`. A restart resumes bitwise
!! identically and refuses a checkpoint made from a different deck or mesh.
module checkpoint
  use kinds, only: wp
  use hdf5, only: hid_t, h5open_f, h5fcreate_f, h5fopen_f, h5fclose_f, h5gcreate_f, h5gopen_f, &
                  h5gclose_f, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F
  use h5io, only: dset_r1, dset_r2, dset_str, attr_int, attr_real, attr_str, &
                  read_r1, read_r2, read_i1, read_str, read_attr_int, read_attr_real
  use contact_types, only: robin_state_t, contact_result_t, checkpointer_t
  use results, only: ensure_parent_dir, atomic_rename, write_history
  implicit none
  private

  !> Checkpoints of the Robin iteration in an HDF5 file, replaced atomically.
  type, extends(checkpointer_t), public :: h5_checkpointer_t
    character(len=:), allocatable :: file   !< where checkpoints go
    character(len=:), allocatable :: key    !< fingerprint of the deck and mesh
    logical :: failed = .false.             !< a checkpoint could not be written
  contains
    procedure :: save => checkpoint_write
  end type h5_checkpointer_t

  public :: checkpoint_read, checkpoint_file

contains

  !> The checkpoint path of a result file: `<file>.ckpt.h5`.
  function checkpoint_file(result_file) result(p)
    character(len=*), intent(in) :: result_file  !< result path
    character(len=:), allocatable :: p
    p = trim(result_file)//'.ckpt.h5'
  end function checkpoint_file

  !> Write the outer state and history.
  subroutine checkpoint_write(self, st, res)
    class(h5_checkpointer_t), intent(inout) :: self  !< target file and key
    type(robin_state_t), intent(in) :: st       !< outer state after iteration st%it
    type(contact_result_t), intent(in) :: res   !< history so far
    integer(hid_t) :: fid, gid
    integer :: err
    character(len=:), allocatable :: tmp
    logical :: ok
    if (.not. allocated(self%file)) return
    call ensure_parent_dir(self%file)
    tmp = self%file//'.tmp'
    call h5open_f(err)
    call h5fcreate_f(tmp, H5F_ACC_TRUNC_F, fid, err)
    if (err /= 0) then
      self%failed = .true.
      return
    end if
    call dset_str(fid, 'key', self%key)
    call attr_str(fid, 'kind', 'robin_contact checkpoint')
    call h5gcreate_f(fid, 'state', gid, err)
    call attr_int(gid, 'it', st%it)
    call attr_int(gid, 'inner', st%inner)
    call attr_int(gid, 'nacc', st%nacc)
    call attr_int(gid, 'stalled', st%stalled)
    call attr_int(gid, 'it_best', st%it_best)
    call attr_real(gid, 'res_best', st%res_best)
    call attr_int(gid, 'inner_maxit_hits', res%inner_maxit_hits)
    call attr_real(gid, 'crit', st%crit)
    call attr_real(gid, 'progress', st%progress)
    call attr_real(gid, 'best', st%best)
    call attr_real(gid, 'omega', st%omega)
    call attr_real(gid, 'wall', st%wall)
    call dset_r1(gid, 'flam', st%flam)
    call dset_r2(gid, 'G', st%G)
    call dset_r2(gid, 'lam', st%lam)
    call dset_r1(gid, 'r_prev', st%r_prev)
    call dset_r1(gid, 'x_prev', st%x_prev)
    call dset_r2(gid, 'dX', st%dX)
    call dset_r2(gid, 'dR', st%dR)
    call attr_int(gid, 'reuse', st%reuse)
    call dset_r2(gid, 'flam_v', st%flam_v)
    call attr_int(gid, 'nsrch', st%nsrch)
    call dset_r2(gid, 'srch', st%srch)
    call dset_r2(gid, 'fsrch', st%fsrch)
    call h5gclose_f(gid, err)
    call write_history(fid, res)
    call h5fclose_f(fid, err)
    call atomic_rename(tmp, self%file, ok)
    if (.not. ok .or. err /= 0) self%failed = .true.
  end subroutine checkpoint_write

  !> Read a checkpoint. ok = .false. with msg if it cannot be read or was made from
  !! another deck or mesh (its key differs from `key`).
  subroutine checkpoint_read(file, key, m, maxout, st, res, ok, msg)
    character(len=*), intent(in) :: file          !< checkpoint path
    character(len=*), intent(in) :: key           !< fingerprint of this run
    integer, intent(in) :: m                      !< interface size of this run
    integer, intent(in) :: maxout                 !< max_outer of this run (history size)
    type(robin_state_t), intent(out) :: st        !< the outer state
    type(contact_result_t), intent(inout) :: res  !< receives the history
    logical, intent(out) :: ok                    !< success
    character(len=*), intent(out) :: msg          !< why not
    integer(hid_t) :: fid, gid
    integer :: err, e(20), ere(2), ers(3), n, i
    character(len=:), allocatable :: k
    real(wp), allocatable :: r(:)
    integer, allocatable :: iv(:)
    logical :: exists

    ok = .false.
    msg = ''
    inquire (file=file, exist=exists)
    if (.not. exists) then
      msg = 'restart file '//trim(file)//' does not exist'
      return
    end if
    call h5open_f(err)
    call h5fopen_f(file, H5F_ACC_RDONLY_F, fid, err)
    if (err /= 0) then
      msg = 'restart file '//trim(file)//' is not an HDF5 file'
      return
    end if
    call read_str(fid, 'key', k, err)
    if (err /= 0) then
      msg = 'restart file '//trim(file)//' is not a robin_contact checkpoint'
      call h5fclose_f(fid, err)
      return
    end if
    if (trim(k) /= trim(key)) then
      msg = 'restart file '//trim(file)//' was made from a different deck or mesh '// &
            '(its bodies, loads, contact or solver settings differ from this run''s)'
      call h5fclose_f(fid, err)
      return
    end if
    e = 0
    call h5gopen_f(fid, 'state', gid, e(1))
    call read_attr_int(gid, 'it', st%it, e(2))
    call read_attr_int(gid, 'inner', st%inner, e(3))
    call read_attr_int(gid, 'nacc', st%nacc, e(4))
    call read_attr_int(gid, 'inner_maxit_hits', res%inner_maxit_hits, e(5))
    call read_attr_int(gid, 'stalled', st%stalled, e(18))
    call read_attr_int(gid, 'it_best', st%it_best, e(19))
    call read_attr_real(gid, 'res_best', st%res_best, e(20))
    call read_attr_real(gid, 'crit', st%crit, e(6))
    call read_attr_real(gid, 'progress', st%progress, e(7))
    call read_attr_real(gid, 'best', st%best, e(8))
    call read_attr_real(gid, 'omega', st%omega, e(9))
    call read_attr_real(gid, 'wall', st%wall, e(10))
    call read_r1(gid, 'flam', r, e(11))
    if (e(11) == 0) st%flam = r(1:2)
    call read_r2(gid, 'G', st%G, e(12))
    call read_r2(gid, 'lam', st%lam, e(13))
    call read_r1(gid, 'r_prev', st%r_prev, e(14))
    call read_r1(gid, 'x_prev', st%x_prev, e(15))
    call read_r2(gid, 'dX', st%dX, e(16))
    call read_r2(gid, 'dR', st%dR, e(17))
    ! F_a lam_a (absent from older checkpoints: recomputed by the first solve)
    call read_attr_int(gid, 'reuse', st%reuse, ere(1))
    call read_r2(gid, 'flam_v', st%flam_v, ere(2))
    if (any(ere /= 0)) st%reuse = 0
    ! the last change of lam_a (absent from older checkpoints: no line search at first)
    call read_attr_int(gid, 'nsrch', st%nsrch, ers(1))
    call read_r2(gid, 'srch', st%srch, ers(2))
    call read_r2(gid, 'fsrch', st%fsrch, ers(3))
    if (any(ers /= 0)) st%nsrch = 0
    call h5gclose_f(gid, err)
    if (any(e /= 0)) then
      msg = 'restart file '//trim(file)//' is incomplete'
      call h5fclose_f(fid, err)
      return
    end if
    if (size(st%G, 1) /= m) then
      msg = 'restart file '//trim(file)//' has a different number of contact nodes'
      call h5fclose_f(fid, err)
      return
    end if
    if (st%reuse == 0) then
      if (allocated(st%flam_v)) deallocate (st%flam_v)
      allocate (st%flam_v(m, 2))
      st%flam_v = 0.0_wp
    end if
    if (st%nsrch /= 0) then
      if (.not. (allocated(st%srch) .and. allocated(st%fsrch))) then
        st%nsrch = 0
      else if (size(st%srch, 1) /= m .or. size(st%fsrch, 1) /= m .or. size(st%srch, 2) /= 2 .or. &
               size(st%fsrch, 2) /= 2) then
        st%nsrch = 0
      end if
    end if
    if (st%nsrch == 0) then
      if (allocated(st%srch)) deallocate (st%srch)
      if (allocated(st%fsrch)) deallocate (st%fsrch)
      allocate (st%srch(m, 2), st%fsrch(m, 2))
      st%srch = 0.0_wp
      st%fsrch = 0.0_wp
    end if
    n = st%it
    if (n > maxout) then
      write (msg, '(a,i0,a,i0)') 'restart file '//trim(file)//' is at outer iteration ', n, &
        ', beyond max_outer = ', maxout
      call h5fclose_f(fid, err)
      return
    end if
    ! history
    if (allocated(res%h_criterion)) deallocate (res%h_criterion, res%h_residual, res%h_wall, res%h_inner, res%h_active)
    allocate (res%h_criterion(maxout), res%h_residual(maxout), res%h_wall(maxout), res%h_inner(maxout), &
              res%h_active(maxout))
    res%h_criterion = 0.0_wp; res%h_residual = 0.0_wp; res%h_wall = 0.0_wp; res%h_inner = 0; res%h_active = 0
    if (allocated(res%lam)) deallocate (res%lam, res%lam_body, res%w, res%gap, res%obstacle)
    allocate (res%lam(m), res%lam_body(m, 2), res%w(m, 2), res%gap(m), res%obstacle(m, 2))
    res%lam = 0.0_wp; res%lam_body = 0.0_wp; res%w = 0.0_wp; res%gap = 0.0_wp; res%obstacle = st%G
    call h5gopen_f(fid, 'history', gid, e(1))
    call read_r1(gid, 'criterion', r, e(2)); if (e(2) == 0) res%h_criterion(1:n) = r(1:n)
    call read_r1(gid, 'residual', r, e(3)); if (e(3) == 0) res%h_residual(1:n) = r(1:n)
    call read_r1(gid, 'wall_s', r, e(4)); if (e(4) == 0) res%h_wall(1:n) = r(1:n)
    call read_i1(gid, 'inner', iv, e(5)); if (e(5) == 0) res%h_inner(1:n) = iv(1:n)
    call read_i1(gid, 'active', iv, e(6)); if (e(6) == 0) res%h_active(1:n) = iv(1:n)
    call h5gclose_f(gid, err)
    call h5fclose_f(fid, err)
    if (any(e(1:6) /= 0)) then
      msg = 'restart file '//trim(file)//' has an incomplete history'
      return
    end if
    res%nhist = n
    res%outer = n
    res%inner = st%inner
    i = 0
    ok = .true.
  end subroutine checkpoint_read

end module checkpoint
