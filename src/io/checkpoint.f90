!> Checkpoint and restart of the outer Robin iteration: the whole outer state
!! (obstacles, contact forces, acceleration history, counters) and the history so
!! far, written atomically to `<result file>.ckpt.h5`. A restart resumes bitwise
!! identically and refuses a checkpoint made from a different deck or mesh.
module checkpoint
  use kinds, only: wp
  use hdf5, only: hid_t
  use h5io, only: h5_status_t, file_open, file_close, group_open, group_close, &
                  write_dset, write_attr, read_dset, read_attr
  use history_io, only: write_history, read_history
  use files, only: temp_name, ensure_parent_dir, atomic_rename, remove_file
  use contact_types, only: robin_state_t, contact_result_t, checkpointer_t
  implicit none (type, external)
  private

  !> Checkpoints of the Robin iteration in an HDF5 file, replaced atomically: a checkpoint
  !! that cannot be written whole leaves the previous one in place.
  type, extends(checkpointer_t), public :: h5_checkpointer_t
    character(len=:), allocatable :: file     !< where checkpoints go
    character(len=:), allocatable :: key      !< fingerprint of the deck and mesh
    logical :: failed = .false.               !< a checkpoint could not be written
    character(len=:), allocatable :: message  !< why the first failed one failed, naming the file
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

  !> Write the outer state and history to a temporary file and rename it over the
  !! previous checkpoint only when complete; on failure remove it and record why.
  subroutine checkpoint_write(self, st, res)
    class(h5_checkpointer_t), intent(inout) :: self  !< target file and key
    type(robin_state_t), intent(in) :: st       !< outer state after iteration st%it
    type(contact_result_t), intent(in) :: res   !< history so far
    integer(hid_t) :: fid, gid
    type(h5_status_t) :: hs
    character(len=:), allocatable :: tmp
    logical :: ok
    if (.not. allocated(self%file)) return
    call ensure_parent_dir(self%file)
    tmp = temp_name(self%file)
    call file_open(tmp, fid, hs, create=.true.)
    call write_dset(fid, 'key', self%key, hs)
    call write_attr(fid, 'kind', 'robin_contact checkpoint', hs)
    call group_open(fid, 'state', gid, hs, create=.true.)
    call write_attr(gid, 'it', st%it, hs)
    call write_attr(gid, 'inner', st%inner, hs)
    call write_attr(gid, 'nacc', st%nacc, hs)
    call write_attr(gid, 'stalled', st%stalled, hs)
    call write_attr(gid, 'it_best', st%it_best, hs)
    call write_attr(gid, 'res_best', st%res_best, hs)
    call write_attr(gid, 'inner_maxit_hits', res%inner_maxit_hits, hs)
    call write_attr(gid, 'crit', st%crit, hs)
    call write_attr(gid, 'progress', st%progress, hs)
    call write_attr(gid, 'best', st%best, hs)
    call write_attr(gid, 'omega', st%omega, hs)
    call write_attr(gid, 'wall', st%wall, hs)
    call write_dset(gid, 'flam', st%flam, hs)
    call write_dset(gid, 'G', st%G, hs)
    call write_dset(gid, 'lam', st%lam, hs)
    call write_dset(gid, 'r_prev', st%r_prev, hs)
    call write_dset(gid, 'x_prev', st%x_prev, hs)
    call write_dset(gid, 'dX', st%dX, hs)
    call write_dset(gid, 'dR', st%dR, hs)
    call write_attr(gid, 'reuse', st%reuse, hs)
    call write_dset(gid, 'flam_v', st%flam_v, hs)
    call write_attr(gid, 'nsrch', st%nsrch, hs)
    call write_dset(gid, 'srch', st%srch, hs)
    call write_dset(gid, 'fsrch', st%fsrch, hs)
    call group_close(gid, hs)
    call write_history(fid, res, hs)
    call file_close(fid, hs)
    ok = .not. hs%failed
    if (ok) then
      call atomic_rename(tmp, self%file, ok)
      if (.not. ok) hs%what = 'failed to rename '//tmp//' to it'
    end if
    if (.not. ok) then
      call remove_file(tmp)
      if (.not. self%failed) self%message = 'a checkpoint could not be written to '//self%file// &
                                            ' ('//hs%what//'); the previous one, if any, is kept'
      self%failed = .true.
    end if
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
    type(h5_status_t) :: hs
    integer :: n
    character(len=:), allocatable :: k
    real(wp), allocatable :: r(:)
    logical :: exists

    ok = .false.
    msg = ''
    inquire (file=file, exist=exists)
    if (.not. exists) then
      msg = 'restart file '//trim(file)//' does not exist'
      return
    end if
    call file_open(file, fid, hs)
    if (hs%failed) then
      msg = 'restart file '//trim(file)//' is not an HDF5 file'
      return
    end if
    call read_dset(fid, 'key', k, hs)
    if (hs%failed) then
      msg = 'restart file '//trim(file)//' is not a robin_contact checkpoint'
    else if (trim(k) /= trim(key)) then
      msg = 'restart file '//trim(file)//' was made from a different deck or mesh '// &
            '(its bodies, loads, contact or solver settings differ from this run''s)'
    else
      call read_state()
    end if
    call file_close(fid, hs)
    ok = len_trim(msg) == 0

  contains

    subroutine read_state()
      call group_open(fid, 'state', gid, hs)
      call read_attr(gid, 'it', st%it, hs)
      call read_attr(gid, 'inner', st%inner, hs)
      call read_attr(gid, 'nacc', st%nacc, hs)
      call read_attr(gid, 'inner_maxit_hits', res%inner_maxit_hits, hs)
      call read_attr(gid, 'stalled', st%stalled, hs)
      call read_attr(gid, 'it_best', st%it_best, hs)
      call read_attr(gid, 'res_best', st%res_best, hs)
      call read_attr(gid, 'crit', st%crit, hs)
      call read_attr(gid, 'progress', st%progress, hs)
      call read_attr(gid, 'best', st%best, hs)
      call read_attr(gid, 'omega', st%omega, hs)
      call read_attr(gid, 'wall', st%wall, hs)
      call read_dset(gid, 'flam', r, hs)
      if (.not. hs%failed) then
        if (size(r) == 2) st%flam = r
      end if
      call read_dset(gid, 'G', st%G, hs)
      call read_dset(gid, 'lam', st%lam, hs)
      call read_dset(gid, 'r_prev', st%r_prev, hs)
      call read_dset(gid, 'x_prev', st%x_prev, hs)
      call read_dset(gid, 'dX', st%dX, hs)
      call read_dset(gid, 'dR', st%dR, hs)
      call read_optional_products()
      call group_close(gid, hs)
      if (hs%failed) then
        msg = 'restart file '//trim(file)//' is incomplete ('//hs%what//')'
        return
      end if
      if (size(st%G, 1) /= m) then
        msg = 'restart file '//trim(file)//' has a different number of contact nodes'
        return
      end if
      n = st%it
      if (n > maxout) then
        write (msg, '(a,i0,a,i0)') 'restart file '//trim(file)//' is at outer iteration ', n, &
          ', beyond max_outer = ', maxout
        return
      end if
      ! history
      if (allocated(res%h_criterion)) deallocate (res%h_criterion, res%h_residual, res%h_wall, res%h_inner, &
                                                  res%h_active)
      allocate (res%h_criterion(maxout), res%h_residual(maxout), res%h_wall(maxout), res%h_inner(maxout), &
                res%h_active(maxout))
      res%h_criterion = 0.0_wp; res%h_residual = 0.0_wp; res%h_wall = 0.0_wp; res%h_inner = 0; res%h_active = 0
      if (allocated(res%lam)) deallocate (res%lam, res%lam_body, res%w, res%gap, res%obstacle)
      allocate (res%lam(m), res%lam_body(m, 2), res%w(m, 2), res%gap(m), res%obstacle(m, 2))
      res%lam = 0.0_wp; res%lam_body = 0.0_wp; res%w = 0.0_wp; res%gap = 0.0_wp; res%obstacle = st%G
      call read_history(fid, n, res, hs)
      if (hs%failed) then
        msg = 'restart file '//trim(file)//' has an incomplete history ('//hs%what//')'
        return
      end if
      res%nhist = n
      res%outer = n
      res%inner = st%inner
    end subroutine read_state

    !> F_a lam_a of the last solves (absent from older checkpoints: then the first solve
    !! after the restart computes it).
    subroutine read_optional_products()
      type(h5_status_t) :: ho
      call read_attr(gid, 'reuse', st%reuse, ho)
      call read_dset(gid, 'flam_v', st%flam_v, ho)
      if (ho%failed) then
        st%reuse = 0
        if (allocated(st%flam_v)) deallocate (st%flam_v)
        allocate (st%flam_v(m, 2))
        st%flam_v = 0.0_wp
      end if
      ! the last change of lam_a and F_a times it (absent from older checkpoints: no line
      ! search in the first iteration after the restart)
      ho%failed = .false.
      call read_attr(gid, 'nsrch', st%nsrch, ho)
      call read_dset(gid, 'srch', st%srch, ho)
      call read_dset(gid, 'fsrch', st%fsrch, ho)
      if (.not. ho%failed) then
        if (any(shape(st%srch) /= [m, 2]) .or. any(shape(st%fsrch) /= [m, 2])) ho%failed = .true.
      end if
      if (ho%failed) then
        st%nsrch = 0
        if (allocated(st%srch)) deallocate (st%srch)
        if (allocated(st%fsrch)) deallocate (st%fsrch)
        allocate (st%srch(m, 2), st%fsrch(m, 2))
        st%srch = 0.0_wp
        st%fsrch = 0.0_wp
      end if
    end subroutine read_optional_products

  end subroutine checkpoint_read

end module checkpoint
