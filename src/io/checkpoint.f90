!> Checkpoint and restart of the outer Robin iteration: the whole outer state
!! (obstacles, contact forces, acceleration history, counters) and the history so
!! far, written atomically to `<result file>.ckpt.h5`. A restart resumes bitwise
!! identically and refuses a checkpoint made from a different deck, from a mesh file
!! whose content has changed since (FNV-1a 64 hash of its bytes), or holding anything
!! that is not what this deck implies (shapes, ranges, NaN or Inf). The file is written
!! in HDF5's latest format, whose metadata carry checksums: a file corrupted in its
!! structure is refused as unreadable, not parsed (HDF5's parser of the default format
!! crashed on some; tests/unit/test_checkpoint.f90). Values corrupted into other finite
!! values within range are not detected.
module checkpoint
  use kinds, only: wp
  use space, only: NRIGID
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use hdf5, only: hid_t, hsize_t
  use h5io, only: file_open, file_close, group_open, group_close, &
                  write_dset, write_attr, read_dset, read_attr, describe, exists, &
                  CLASS_INTEGER, CLASS_REAL, CLASS_STRING, CLASS_VSTRING
  use errors, only: error_t, ERR_INPUT, ERR_IO
  use strings, only: i2s
  use digest, only: file_digest
  use history_io, only: write_history, read_history
  use files, only: temp_name, ensure_parent_dir, atomic_rename, remove_file
  use contact_types, only: robin_state_t, contact_result_t, checkpointer_t, recycle_size, STATUS_CONVERGED
  use results, only: step_result_t
  implicit none (type, external)
  private

  !> Checkpoints of the Robin iteration in an HDF5 file, replaced atomically: a checkpoint
  !! that cannot be written whole leaves the previous one in place.
  type, extends(checkpointer_t), public :: h5_checkpointer_t
    character(len=:), allocatable :: file     !< where checkpoints go
    character(len=:), allocatable :: key      !< fingerprint of the deck
    character(len=:), allocatable :: meshes   !< content hashes of the mesh files (mesh_identity; '' none)
    type(error_t) :: err                      !< why the first checkpoint that failed failed (ERR_IO), naming the file
    !> In a load history (&solver load_steps): the step being solved (0: a run of one step)
    !! and the converged results of the steps before it, which a restart replays (pointing
    !! at the run's own: a step copies none of them, so a long history stays linear)
    integer :: step = 0
    !> whole step records, not their %res component: a pointer to a component of an
    !! array section lost its stride with gfortran 12 (the second step's record read
    !! from the wrong place: a load history signalled after two steps crashed here)
    type(step_result_t), pointer :: done(:) => null()
  contains
    procedure :: save => checkpoint_write
  end type h5_checkpointer_t

  public :: checkpoint_read, checkpoint_read_steps, checkpoint_file, mesh_identity

  integer(hsize_t), parameter :: SCALAR(0) = [integer(hsize_t) ::]
  character(len=*), parameter :: INT_ATTRS(7) = [character(len=16) :: 'it', 'inner', 'nacc', 'stalled', &
                                                 'it_best', 'inner_maxit_hits', 'equality_updates']
  character(len=*), parameter :: REAL_ATTRS(6) = [character(len=16) :: 'res_best', 'crit', 'progress', &
                                                  'best', 'omega', 'wall']

  !> A checkpoint being read: the open file and groups, what this run implies of it, what
  !! it was found to hold, and the first thing wrong with it (msg, '' while all is well).
  type :: ckpt_reader_t
    character(len=:), allocatable :: src       ! 'restart file <path>', for messages
    character(len=:), allocatable :: msg       ! why it cannot be used
    integer(hid_t) :: fid = -1, gid = -1, hid = -1   ! the file, /state, /history
    type(error_t) :: hs
    integer :: m = 0                           ! interface size of this run
    integer :: maxout = 0                      ! max_outer of this run
    integer :: nh = 0                          ! entries of /history
    integer :: kr = 0                          ! stored directions per body
    integer :: nbody = 2                       ! bodies of this run
    integer :: depth = 5                       ! Anderson depth of this run
    logical :: has_products = .false., has_search = .false., has_recycle = .false., has_mu = .false.
    logical :: has_newton = .false.
    logical :: has_kept = .false.
    logical :: has_rows = .false.
    logical, allocatable :: signed(:)    ! rows whose force may be negative (friction's tangential rows)
  end type ckpt_reader_t

contains

  !> The checkpoint path of a result file: `<file>.ckpt.h5`.
  function checkpoint_file(result_file) result(p)
    character(len=*), intent(in) :: result_file  !< result path
    character(len=:), allocatable :: p
    p = trim(result_file)//'.ckpt.h5'
  end function checkpoint_file

  !> The identity of the mesh files a deck reads: one line `<hash>  <path>` per distinct
  !! file (hash: FNV-1a 64 of its bytes, 16 hex digits), lines joined by a newline; ''
  !! when the deck reads none. err (ERR_IO) when a file cannot be read whole.
  subroutine mesh_identity(paths, text, err, known)
    character(len=*), intent(in) :: paths(:)            !< each body's mesh file ('' none)
    character(len=:), allocatable, intent(out) :: text  !< the identity
    type(error_t), intent(out) :: err                   !< why a file could not be hashed
    !> each body's file's hash where already known (the reader's, of the bytes it parsed;
    !! '': the file is read again and hashed)
    character(len=16), intent(in), optional :: known(:)
    character(len=16) :: hex
    integer :: a
    text = ''
    do a = 1, size(paths)
      if (len_trim(paths(a)) == 0) cycle
      if (any(paths(1:a - 1) == paths(a))) cycle
      hex = ''
      if (present(known)) hex = known(a)
      if (len_trim(hex) == 0) call file_digest(trim(paths(a)), hex, err)
      if (err%failed()) return
      if (len(text) > 0) text = text//achar(10)
      text = text//hex//'  '//trim(paths(a))
    end do
  end subroutine mesh_identity

  !> Write the outer state and history to a temporary file and rename it over the
  !! previous checkpoint only when complete; on failure remove it and record why.
  subroutine checkpoint_write(self, st, res)
    class(h5_checkpointer_t), intent(inout) :: self  !< target file and key
    type(robin_state_t), intent(in) :: st       !< outer state after iteration st%it
    type(contact_result_t), intent(in) :: res   !< history so far
    integer(hid_t) :: fid, gid
    type(error_t) :: hs, moved
    character(len=:), allocatable :: tmp
    logical :: ok
    if (.not. allocated(self%file)) return
    call ensure_parent_dir(self%file)
    tmp = temp_name(self%file)
    call file_open(tmp, fid, hs, create=.true., checksums=.true.)
    call write_dset(fid, 'key', self%key, hs)
    if (allocated(self%meshes)) then
      if (len(self%meshes) > 0) call write_dset(fid, 'mesh_files', self%meshes, hs)
    end if
    call write_attr(fid, 'kind', 'robin_contact checkpoint', hs)
    call group_open(fid, 'state', gid, hs, create=.true.)
    call write_attr(gid, 'it', st%it, hs)
    call write_attr(gid, 'inner', st%inner, hs)
    call write_attr(gid, 'nacc', st%nacc, hs)
    call write_attr(gid, 'stalled', st%stalled, hs)
    call write_attr(gid, 'it_best', st%it_best, hs)
    call write_attr(gid, 'res_best', st%res_best, hs)
    call write_attr(gid, 'inner_maxit_hits', res%inner_maxit_hits, hs)
    call write_attr(gid, 'equality_updates', res%eq_updates, hs)
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
    call write_attr(gid, 'settled', st%settled, hs)
    call write_dset(gid, 'row_state', st%row_state, hs)
    call write_dset(gid, 'nrw', reshape(st%nrw, [size(st%nrw)]), hs)
    call write_dset(gid, 'newton', st%newton, hs)
    call write_dset(gid, 'kept', st%kept, hs)
    call write_dset(gid, 'rw', st%rw, hs)
    call write_dset(gid, 'raw', st%raw, hs)
    call write_dset(gid, 'mu', st%eq_mult, hs)   ! the dataset keeps its name: earlier checkpoints read the same
    call group_close(gid, hs)
    call write_history(fid, res, hs)
    if (self%step > 0) call write_load_history(fid, self%step, self%done, hs)
    call file_close(fid, hs)
    ok = .not. hs%failed()
    if (ok) then
      call atomic_rename(tmp, self%file, moved)
      ok = .not. moved%failed()
      if (.not. ok) call hs%set(ERR_IO, 'failed to rename '//tmp//' to it')
    end if
    if (.not. ok) then
      call remove_file(tmp)
      if (.not. self%err%failed()) call self%err%set(ERR_IO, 'a checkpoint could not be written to '//self%file// &
                                                     ' ('//hs%text()//'); the previous one, if any, is kept')
    end if
  end subroutine checkpoint_write

  !> Read a checkpoint. err (ERR_INPUT) if it cannot be read, was made from another deck
  !! (its key differs from `key`) or from mesh files whose content has changed since
  !! (`meshes`, from mesh_identity), or does not hold what this deck implies. Nothing in
  !! the file is trusted: before anything is read, every dataset and attribute is checked
  !! for its type class and shape (m contact nodes, the Anderson depth, a history of at least
  !! `it` and at most max_outer entries), and after reading, the counters for their ranges
  !! and every real dataset and attribute for finite values; the message names the file
  !! and the object.
  subroutine checkpoint_read(file, key, meshes, m, nbody, depth, maxout, st, res, err, signed)
    character(len=*), intent(in) :: file          !< checkpoint path
    character(len=*), intent(in) :: key           !< fingerprint of this run
    character(len=*), intent(in) :: meshes        !< this run's mesh_identity
    integer, intent(in) :: m                      !< contact rows of this run (all pairs)
    integer, intent(in) :: nbody                  !< bodies of this run
    integer, intent(in) :: depth                  !< Anderson depth of this run (contact_types anderson_history)
    integer, intent(in) :: maxout                 !< max_outer of this run (history size)
    type(robin_state_t), intent(out) :: st        !< the outer state
    type(contact_result_t), intent(inout) :: res  !< receives the history and the counters
    type(error_t), intent(out) :: err             !< why it cannot be used
    logical, intent(in), optional :: signed(:)    !< (m) rows whose force may be negative (tangential rows)
    type(ckpt_reader_t) :: r
    character(len=:), allocatable :: k
    logical :: exists_

    r%msg = ''
    r%src = 'restart file '//trim(file)
    allocate (r%signed(m))
    r%signed = .false.
    if (present(signed)) r%signed = signed
    r%m = m
    r%nbody = nbody
    r%depth = depth
    r%maxout = maxout
    inquire (file=file, exist=exists_)
    if (.not. exists_) then
      call err%set(ERR_INPUT, r%src//' does not exist')
      return
    end if
    call file_open(file, r%fid, r%hs)
    if (r%hs%failed()) then
      call err%set(ERR_INPUT, r%src//' is not an HDF5 file')
      return
    end if
    if (.not. exists(r%fid, 'key', .false.)) then
      r%msg = r%src//' is not a robin_contact checkpoint (it has no dataset /key)'
    else
      call need(r, r%fid, '/', 'key', .false., CLASS_STRING, SCALAR, 'a scalar string')
    end if
    if (len_trim(r%msg) == 0) then
      call read_dset(r%fid, 'key', k, r%hs)
      if (r%hs%failed()) then
        r%msg = r%src//' is not a robin_contact checkpoint ('//r%hs%text()//')'
      else if (trim(k) /= trim(key)) then
        r%msg = r%src//' was made from a different deck or mesh '// &
                '(its bodies, loads, contact or solver settings differ from this run''s)'
      end if
    end if
    if (len_trim(r%msg) == 0) call check_meshes(r, meshes)
    if (len_trim(r%msg) == 0) call check_layout(r)
    if (len_trim(r%msg) == 0) call read_state(r, st, res)
    call group_close(r%hid, r%hs)
    call group_close(r%gid, r%hs)
    call file_close(r%fid, r%hs)
    if (len_trim(r%msg) > 0) call err%set(ERR_INPUT, r%msg)
  end subroutine checkpoint_read

  !> /load_history: the step being solved (attribute step) and, for each step k before it,
  !! group step_<k> with its converged contact result (forces, interface displacements,
  !! gap, obstacles, rigid amplitudes; status and counts as attributes).
  subroutine write_load_history(fid, step, done, hs)
    integer(hid_t), intent(in) :: fid
    integer, intent(in) :: step
    type(step_result_t), intent(in) :: done(:)
    type(error_t), intent(inout) :: hs
    integer(hid_t) :: lid, kid
    integer :: k
    call group_open(fid, 'load_history', lid, hs, create=.true.)
    call write_attr(lid, 'step', step, hs)
    do k = 1, step - 1
      call group_open(lid, 'step_'//i2s(k), kid, hs, create=.true.)
      call write_attr(kid, 'status', done(k)%res%status, hs)
      call write_attr(kid, 'outer', done(k)%res%outer, hs)
      call write_attr(kid, 'inner', done(k)%res%inner, hs)
      call write_attr(kid, 'residual', done(k)%res%residual, hs)
      call write_dset(kid, 'lam', done(k)%res%lam, hs)
      call write_dset(kid, 'lam_body', done(k)%res%lam_body, hs)
      call write_dset(kid, 'w', done(k)%res%w, hs)
      call write_dset(kid, 'gap', done(k)%res%gap, hs)
      call write_dset(kid, 'obstacle', done(k)%res%obstacle, hs)
      call write_dset(kid, 'rigid', done(k)%res%rigid, hs)
      call group_close(kid, hs)
    end do
    call group_close(lid, hs)
  end subroutine write_load_history

  !> The load history of a checkpoint of a run of nstep load steps: the step it resumes
  !! (`step`) and the converged results of the steps before it (`done`). Checked as the
  !! rest of the checkpoint: err (ERR_INPUT) naming the file and the object when the group
  !! is missing, a shape is not this deck's (m contact nodes, nbody bodies), a value is not
  !! finite, the step is outside 1 .. nstep, or a step before it did not converge.
  subroutine checkpoint_read_steps(file, m, nbody, nstep, step, done, err)
    character(len=*), intent(in) :: file                       !< checkpoint path (read by checkpoint_read)
    integer, intent(in) :: m                                   !< contact rows of this run
    integer, intent(in) :: nbody                               !< bodies of this run
    integer, intent(in) :: nstep                               !< load steps of this run
    integer, intent(out) :: step                               !< the step to resume
    type(contact_result_t), allocatable, intent(out) :: done(:) !< (step - 1) the steps before it
    type(error_t), intent(out) :: err                          !< why it cannot be used
    type(ckpt_reader_t) :: r
    integer(hid_t) :: lid, kid
    integer(hsize_t) :: m2
    integer :: k
    character(len=:), allocatable :: path
    step = 0
    allocate (done(0))
    r%msg = ''
    r%src = 'restart file '//trim(file)
    m2 = int(m, hsize_t)
    call file_open(file, r%fid, r%hs)
    if (r%hs%failed()) then
      call err%set(ERR_INPUT, r%src//' is not an HDF5 file')
      return
    end if
    lid = -1
    if (.not. exists(r%fid, 'load_history', .false.)) then
      r%msg = r%src//' has no group /load_history: it is not from a run of '//i2s(nstep)//' load steps'
    else
      call group_open(r%fid, 'load_history', lid, r%hs)
      call need(r, lid, '/load_history', 'step', .true., CLASS_INTEGER, SCALAR, 'a scalar')
    end if
    if (len_trim(r%msg) == 0) then
      call read_attr(lid, 'step', step, r%hs)
      if (step < 1 .or. step > nstep) r%msg = r%src//': attribute step of /load_history is '//i2s(step)// &
                                              ', outside 1 .. '//i2s(nstep)//' (the load steps of this deck)'
    end if
    if (len_trim(r%msg) == 0) then
      deallocate (done)
      allocate (done(step - 1))
      do k = 1, step - 1
        path = '/load_history/step_'//i2s(k)
        if (.not. exists(lid, 'step_'//i2s(k), .false.)) then
          r%msg = r%src//' has no group '//path//' (the steps before the one it resumes)'
          exit
        end if
        call group_open(lid, 'step_'//i2s(k), kid, r%hs)
        call need(r, kid, path, 'status', .true., CLASS_INTEGER, SCALAR, 'a scalar')
        call need(r, kid, path, 'outer', .true., CLASS_INTEGER, SCALAR, 'a scalar')
        call need(r, kid, path, 'inner', .true., CLASS_INTEGER, SCALAR, 'a scalar')
        call need(r, kid, path, 'residual', .true., CLASS_REAL, SCALAR, 'a scalar')
        call need(r, kid, path, 'lam', .false., CLASS_REAL, [m2], contact_nodes(m))
        call need(r, kid, path, 'lam_body', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(m))
        call need(r, kid, path, 'w', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(m))
        call need(r, kid, path, 'gap', .false., CLASS_REAL, [m2], contact_nodes(m))
        call need(r, kid, path, 'obstacle', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(m))
        call need(r, kid, path, 'rigid', .false., CLASS_REAL, [int(NRIGID, hsize_t), int(nbody, hsize_t)], &
                  'one amplitude per rigid motion and body')
        if (len_trim(r%msg) == 0) then
          associate (d => done(k))
            call read_attr(kid, 'status', d%status, r%hs)
            call read_attr(kid, 'outer', d%outer, r%hs)
            call read_attr(kid, 'inner', d%inner, r%hs)
            call read_attr(kid, 'residual', d%residual, r%hs)
            call read_dset(kid, 'lam', d%lam, r%hs)
            call read_dset(kid, 'lam_body', d%lam_body, r%hs)
            call read_dset(kid, 'w', d%w, r%hs)
            call read_dset(kid, 'gap', d%gap, r%hs)
            call read_dset(kid, 'obstacle', d%obstacle, r%hs)
            call read_dset(kid, 'rigid', d%rigid, r%hs)
            if (r%hs%failed()) then
              r%msg = r%src//' cannot be read ('//r%hs%text()//')'
            else if (d%status /= STATUS_CONVERGED) then
              r%msg = r%src//': attribute status of '//path//' is '//i2s(d%status)//', not converged'
            else if (min(d%outer, d%inner) < 0) then
              r%msg = r%src//': attribute outer or inner of '//path//' is negative'
            end if
            call need_finite(r, 'attribute residual of '//path, [d%residual])
            call need_finite(r, 'dataset '//path//'/lam', d%lam)
            call need_finite(r, 'dataset '//path//'/lam_body', d%lam_body)
            call need_finite(r, 'dataset '//path//'/w', d%w)
            call need_finite(r, 'dataset '//path//'/gap', d%gap)
            call need_finite(r, 'dataset '//path//'/obstacle', d%obstacle)
            call need_finite(r, 'dataset '//path//'/rigid', d%rigid)
          end associate
        end if
        call group_close(kid, r%hs)
        if (len_trim(r%msg) > 0) exit
      end do
    end if
    if (lid /= -1) call group_close(lid, r%hs)
    call file_close(r%fid, r%hs)
    if (len_trim(r%msg) > 0) call err%set(ERR_INPUT, r%msg)
  end subroutine checkpoint_read_steps

  !> Each mesh file of this run (a line `<hash>  <path>` of `meshes`) must have the hash
  !! the checkpoint's /mesh_files records for its path: the file has not changed since.
  !! (Its path is in the key, compared before.)
  subroutine check_meshes(r, meshes)
    type(ckpt_reader_t), intent(inout) :: r
    character(len=*), intent(in) :: meshes
    character(len=:), allocatable :: stored, line, path, had
    integer :: i0, i1
    if (len(meshes) == 0) return
    if (.not. exists(r%fid, 'mesh_files', .false.)) then
      r%msg = r%src//' has no dataset /mesh_files (the content hashes of the mesh files it was made from), '// &
              'so it cannot be checked against mesh file '//first_path(meshes)//'; start the run afresh'
      return
    end if
    call need(r, r%fid, '/', 'mesh_files', .false., CLASS_STRING, SCALAR, 'a scalar string')
    if (len_trim(r%msg) > 0) return
    call read_dset(r%fid, 'mesh_files', stored, r%hs)
    if (r%hs%failed()) then
      r%msg = r%src//': dataset /mesh_files cannot be read ('//r%hs%text()//')'
      return
    end if
    i0 = 1
    do while (i0 <= len(meshes))
      i1 = line_end(meshes, i0)
      line = meshes(i0:i1 - 1)
      path = line(19:)
      had = stored_hash(stored, path)
      if (len(had) == 0) then
        r%msg = r%src//': dataset /mesh_files has no content hash for mesh file '//path
        return
      else if (had /= line(1:16)) then
        r%msg = 'mesh file '//path//' changed since the checkpoint was written (content hash '//line(1:16)// &
                ', the checkpoint''s '//had//'): '//r%src//' belongs to the mesh it replaced; start the run afresh'
        return
      end if
      i0 = i1 + 1
    end do
  end subroutine check_meshes

  !> The position of the newline ending the line that starts at i0 of `text` (len + 1 on
  !! the last line without one).
  pure integer function line_end(text, i0)
    character(len=*), intent(in) :: text
    integer, intent(in) :: i0
    line_end = index(text(i0:), achar(10))
    if (line_end == 0) then
      line_end = len(text) + 1
    else
      line_end = i0 + line_end - 1
    end if
  end function line_end

  !> The hash that the /mesh_files text `stored` records for `path` ('' none).
  function stored_hash(stored, path) result(h)
    character(len=*), intent(in) :: stored, path
    character(len=:), allocatable :: h
    integer :: i0, i1
    h = ''
    i0 = 1
    do while (i0 <= len(stored))
      i1 = line_end(stored, i0)
      if (i1 - i0 >= 18) then
        if (stored(i0 + 18:i1 - 1) == path) then
          h = stored(i0:i0 + 15)
          return
        end if
      end if
      i0 = i1 + 1
    end do
  end function stored_hash

  !> The path of the first line of a mesh_identity text.
  function first_path(meshes) result(p)
    character(len=*), intent(in) :: meshes
    character(len=:), allocatable :: p
    integer :: i1
    i1 = index(meshes, achar(10))
    if (i1 == 0) i1 = len(meshes) + 1
    p = meshes(19:i1 - 1)
  end function first_path

  !> Every object the state is read from, checked for class and shape before reading.
  subroutine check_layout(r)
    type(ckpt_reader_t), intent(inout) :: r
    integer(hsize_t) :: m2, hdims(1)
    integer(hsize_t), allocatable :: dims(:)
    integer :: cls, j
    integer(hid_t) :: g
    character(len=*), parameter :: hist(5) = [character(len=9) :: 'criterion', 'residual', 'wall_s', &
                                              'inner', 'active']
    m2 = int(r%m, hsize_t)
    call open_group(r, 'state', g)
    r%gid = g
    call open_group(r, 'history', g)
    r%hid = g
    if (len_trim(r%msg) > 0) return
    do j = 1, size(INT_ATTRS)
      call need(r, r%gid, '/state', trim(INT_ATTRS(j)), .true., CLASS_INTEGER, SCALAR, 'a scalar')
    end do
    do j = 1, size(REAL_ATTRS)
      call need(r, r%gid, '/state', trim(REAL_ATTRS(j)), .true., CLASS_REAL, SCALAR, 'a scalar')
    end do
    call need(r, r%gid, '/state', 'flam', .false., CLASS_REAL, [int(r%nbody, hsize_t)], 'one per body')
    call need(r, r%gid, '/state', 'G', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(r%m))
    call need(r, r%gid, '/state', 'lam', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(r%m))
    call need(r, r%gid, '/state', 'r_prev', .false., CLASS_REAL, [2*m2], contact_nodes(r%m))
    call need(r, r%gid, '/state', 'x_prev', .false., CLASS_REAL, [2*m2], contact_nodes(r%m))
    call need(r, r%gid, '/state', 'dX', .false., CLASS_REAL, [2*m2, int(r%depth, hsize_t)], &
              contact_nodes(r%m)//' and Anderson depth '//i2s(r%depth))
    call need(r, r%gid, '/state', 'dR', .false., CLASS_REAL, [2*m2, int(r%depth, hsize_t)], &
              contact_nodes(r%m)//' and Anderson depth '//i2s(r%depth))
    ! F_a lam_a of the last solves: absent from older checkpoints, checked when present
    r%has_products = exists(r%gid, 'reuse', .true.) .or. exists(r%gid, 'flam_v', .false.)
    if (r%has_products) then
      call need(r, r%gid, '/state', 'reuse', .true., CLASS_INTEGER, SCALAR, 'a scalar')
      call need(r, r%gid, '/state', 'flam_v', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(r%m))
    end if
    ! the last change of lam_a and F_a times it: absent from older checkpoints, checked when present
    r%has_search = exists(r%gid, 'nsrch', .true.) .or. exists(r%gid, 'srch', .false.) .or. exists(r%gid, 'fsrch', .false.)
    if (r%has_search) then
      call need(r, r%gid, '/state', 'nsrch', .true., CLASS_INTEGER, SCALAR, 'a scalar')
      call need(r, r%gid, '/state', 'srch', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(r%m))
      call need(r, r%gid, '/state', 'fsrch', .false., CLASS_REAL, [m2, 2_hsize_t], contact_nodes(r%m))
    end if
    ! friction's row bound states: absent from older checkpoints, checked when present
    r%has_rows = exists(r%gid, 'settled', .true.) .or. exists(r%gid, 'row_state', .false.)
    if (r%has_rows) then
      call need(r, r%gid, '/state', 'settled', .true., CLASS_INTEGER, SCALAR, 'a scalar')
      call need(r, r%gid, '/state', 'row_state', .false., CLASS_INTEGER, [m2], contact_nodes(r%m))
    end if
    ! the stored directions of the bodies' solves and their images: absent from older
    ! checkpoints, checked when present
    r%kr = recycle_size(r%m)
    r%has_recycle = exists(r%gid, 'nrw', .false.) .or. exists(r%gid, 'rw', .false.) .or. exists(r%gid, 'raw', .false.)
    if (r%has_recycle) then
      call need(r, r%gid, '/state', 'nrw', .false., CLASS_INTEGER, [int(2*r%nbody, hsize_t)], 'two counters per body')
      call need(r, r%gid, '/state', 'rw', .false., CLASS_REAL, [m2, int(2*r%kr, hsize_t)], &
                contact_nodes(r%m)//' and '//i2s(r%kr)//' directions per body')
      call need(r, r%gid, '/state', 'raw', .false., CLASS_REAL, [m2, int(2*r%kr, hsize_t)], &
                contact_nodes(r%m)//' and '//i2s(r%kr)//' directions per body')
    end if
    ! the bodies' choice of inner solver: absent from older checkpoints
    r%has_newton = exists(r%gid, 'newton', .false.)
    if (r%has_newton) call need(r, r%gid, '/state', 'newton', .false., CLASS_INTEGER, [int(r%nbody, hsize_t)], &
                                'one flag per body')
    r%has_kept = exists(r%gid, 'kept', .false.)
    if (r%has_kept) call need(r, r%gid, '/state', 'kept', .false., CLASS_INTEGER, [int(r%nbody, hsize_t)], &
                              'one flag per body')
    ! the equality multipliers of floating bodies: absent from older checkpoints
    r%has_mu = exists(r%gid, 'mu', .false.)
    if (r%has_mu) call need(r, r%gid, '/state', 'mu', .false., CLASS_REAL, [int(NRIGID, hsize_t), int(r%nbody, hsize_t)], &
                          'one multiplier per rigid motion and body')
    if (len_trim(r%msg) > 0) return
    ! the history: five arrays of one length r%nh, it <= r%nh <= max_outer (checked after reading it)
    call need(r, r%hid, '/history', 'criterion', .false., CLASS_REAL, [-1_hsize_t], 'one entry per outer iteration')
    if (len_trim(r%msg) > 0) return
    call describe(r%hid, 'criterion', .false., cls, dims, r%hs)
    hdims = dims
    do j = 1, size(hist)
      call need(r, r%hid, '/history', trim(hist(j)), .false., merge(CLASS_INTEGER, CLASS_REAL, j > 3), hdims, &
                'one entry per outer iteration, as /history/criterion')
    end do
    r%nh = int(hdims(1))
    if (len_trim(r%msg) == 0 .and. r%nh > r%maxout) &
      r%msg = r%src//': dataset /history/criterion has '//i2s(r%nh)//' entries, more than max_outer = '//i2s(r%maxout)
  end subroutine check_layout

  !> Open group `name` of the file into g; r%msg when it is not there.
  subroutine open_group(r, name, g)
    type(ckpt_reader_t), intent(inout) :: r
    character(len=*), intent(in) :: name
    integer(hid_t), intent(out) :: g
    g = -1
    if (len_trim(r%msg) > 0) return
    if (.not. exists(r%fid, name, .false.)) then
      r%msg = r%src//' has no group /'//name
      return
    end if
    call group_open(r%fid, name, g, r%hs)
    if (r%hs%failed()) r%msg = r%src//': '//r%hs%text()
  end subroutine open_group

  !> Check that `name` in `loc` (path `path`) is a dataset, or an attribute when `attr`, of
  !! class `cls` and shape `dims` (Fortran order; -1: any extent); `what` says what the
  !! shape stands for. On the first mismatch r%msg names the file and the object.
  subroutine need(r, loc, path, name, attr, cls, dims, what)
    type(ckpt_reader_t), intent(inout) :: r
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: path, name, what
    logical, intent(in) :: attr
    integer, intent(in) :: cls
    integer(hsize_t), intent(in) :: dims(:)
    integer(hsize_t), allocatable :: got(:)
    integer :: c
    character(len=:), allocatable :: obj
    type(error_t) :: ds
    if (len_trim(r%msg) > 0) return
    if (attr) then
      obj = 'attribute '//trim(name)//' of '//path
    else
      obj = 'dataset '//path//'/'//name
      if (path == '/') obj = 'dataset /'//name
    end if
    if (.not. exists(loc, name, attr)) then
      r%msg = r%src//' has no '//obj
      return
    end if
    call describe(loc, name, attr, c, got, ds)
    if (ds%failed()) then
      r%msg = r%src//': '//ds%text()
    else if (c /= cls) then
      r%msg = r%src//': '//obj//' holds '//class_name(c)//', expected '//class_name(cls)
    else if (size(got) /= size(dims)) then
      r%msg = r%src//': '//obj//' has shape '//shape_text(got)//', expected '//shape_text(dims)//' ('//what//')'
    else if (any(got /= dims .and. dims >= 0)) then
      r%msg = r%src//': '//obj//' has shape '//shape_text(got)//', expected '//shape_text(dims)//' ('//what//')'
    end if
  end subroutine need

  function contact_nodes(m) result(t)
    integer, intent(in) :: m
    character(len=:), allocatable :: t
    t = 'this deck has '//i2s(m)//' contact nodes'
  end function contact_nodes

  subroutine read_state(r, st, res)
    type(ckpt_reader_t), intent(inout) :: r
    type(robin_state_t), intent(inout) :: st
    type(contact_result_t), intent(inout) :: res
    real(wp), allocatable :: rv(:), rmu(:, :)
    integer, allocatable :: ir(:)
    integer :: n, m
    m = r%m
    call read_attr(r%gid, 'it', st%it, r%hs)
    call read_attr(r%gid, 'inner', st%inner, r%hs)
    call read_attr(r%gid, 'nacc', st%nacc, r%hs)
    call read_attr(r%gid, 'inner_maxit_hits', res%inner_maxit_hits, r%hs)
    call read_attr(r%gid, 'equality_updates', res%eq_updates, r%hs)
    call read_attr(r%gid, 'stalled', st%stalled, r%hs)
    call read_attr(r%gid, 'it_best', st%it_best, r%hs)
    call read_attr(r%gid, 'res_best', st%res_best, r%hs)
    call read_attr(r%gid, 'crit', st%crit, r%hs)
    call read_attr(r%gid, 'progress', st%progress, r%hs)
    call read_attr(r%gid, 'best', st%best, r%hs)
    call read_attr(r%gid, 'omega', st%omega, r%hs)
    call read_attr(r%gid, 'wall', st%wall, r%hs)
    call read_dset(r%gid, 'flam', rv, r%hs)
    if (.not. r%hs%failed()) st%flam = rv
    call read_dset(r%gid, 'G', st%G, r%hs)
    call read_dset(r%gid, 'lam', st%lam, r%hs)
    call read_dset(r%gid, 'r_prev', st%r_prev, r%hs)
    call read_dset(r%gid, 'x_prev', st%x_prev, r%hs)
    call read_dset(r%gid, 'dX', st%dX, r%hs)
    call read_dset(r%gid, 'dR', st%dR, r%hs)
    if (r%has_products) then
      call read_attr(r%gid, 'reuse', st%reuse, r%hs)
      call read_dset(r%gid, 'flam_v', st%flam_v, r%hs)
    else
      ! an older checkpoint: the first solve after the restart computes F_a lam_a
      st%reuse = 0
      allocate (st%flam_v(m, 2))
      st%flam_v = 0.0_wp
    end if
    if (r%has_search) then
      call read_attr(r%gid, 'nsrch', st%nsrch, r%hs)
      call read_dset(r%gid, 'srch', st%srch, r%hs)
      call read_dset(r%gid, 'fsrch', st%fsrch, r%hs)
    else
      ! an older checkpoint: no line search in the first iteration after the restart
      st%nsrch = 0
      allocate (st%srch(m, 2), st%fsrch(m, 2))
      st%srch = 0.0_wp
      st%fsrch = 0.0_wp
    end if
    if (r%has_rows) then
      call read_attr(r%gid, 'settled', st%settled, r%hs)
      call read_dset(r%gid, 'row_state', st%row_state, r%hs)
    else
      ! an older checkpoint: the rows' states are learnt again in the first iterations
      st%settled = 0
      allocate (st%row_state(m))
      st%row_state = -1
    end if
    allocate (st%eq_mult(NRIGID, r%nbody), st%nrw(2, r%nbody))
    allocate (st%newton(r%nbody), st%kept(r%nbody), source=0)
    if (r%has_newton) then
      call read_dset(r%gid, 'newton', ir, r%hs)
      if (.not. r%hs%failed()) st%newton = ir
    end if
    ! the kept factors (absent from older checkpoints: none, made again when needed)
    if (r%has_kept) then
      call read_dset(r%gid, 'kept', ir, r%hs)
      if (.not. r%hs%failed()) st%kept = merge(1, 0, ir /= 0)
    end if
    st%eq_mult = 0.0_wp
    if (r%has_mu) then
      call read_dset(r%gid, 'mu', rmu, r%hs)
      if (.not. r%hs%failed()) st%eq_mult = rmu
    end if
    if (r%has_recycle) then
      call read_dset(r%gid, 'nrw', ir, r%hs)
      if (.not. r%hs%failed()) st%nrw = reshape(ir, [2, r%nbody])
      call read_dset(r%gid, 'rw', st%rw, r%hs)
      call read_dset(r%gid, 'raw', st%raw, r%hs)
    else
      ! an older checkpoint: the bodies' solves start again without stored directions
      st%nrw(1, :) = 0
      st%nrw(2, :) = 1
      allocate (st%rw(m, 2*r%kr), st%raw(m, 2*r%kr))
      st%rw = 0.0_wp
      st%raw = 0.0_wp
    end if
    if (r%hs%failed()) then
      r%msg = r%src//' cannot be read ('//r%hs%text()//')'
      return
    end if
    ! ranges of the counters, finite values
    n = st%it
    if (n < 1 .or. n > r%maxout) then
      r%msg = r%src//': attribute it of /state is '//i2s(n)//', outside 1 .. max_outer = '//i2s(r%maxout)
    else if (n > r%nh) then
      r%msg = r%src//': attribute it of /state is '//i2s(n)//', beyond the '//i2s(r%nh)// &
            ' entries of /history/criterion'
    else if (min(st%inner, st%nacc, st%stalled, res%inner_maxit_hits, res%eq_updates) < 0) then
      r%msg = r%src//': a counter of /state (inner, nacc, stalled, inner_maxit_hits, equality_updates) is negative'
    else if (st%it_best < 0 .or. st%it_best > n) then
      r%msg = r%src//': attribute it_best of /state is '//i2s(st%it_best)//', outside 0 .. it = '//i2s(n)
    else if (st%reuse /= 0 .and. st%reuse /= 1) then
      r%msg = r%src//': attribute reuse of /state is '//i2s(st%reuse)//', not 0 or 1'
    else if (any(st%nrw(1, :) < 0 .or. st%nrw(1, :) > r%kr .or. st%nrw(2, :) < 1 .or. st%nrw(2, :) > max(1, r%kr))) then
      r%msg = r%src//': dataset /state/nrw holds counters outside 0 .. '//i2s(r%kr)//' (held) or 1 .. '// &
            i2s(max(1, r%kr))//' (next slot)'
    else if (st%settled /= 0 .and. st%settled /= 1) then
      r%msg = r%src//': attribute settled of /state is '//i2s(st%settled)//', not 0 or 1'
    else if (any(st%row_state < -1 .or. st%row_state > 15)) then
      r%msg = r%src//': dataset row_state of /state holds a value outside -1 .. 15'
    else if (st%nsrch /= 0 .and. st%nsrch /= 1) then
      r%msg = r%src//': attribute nsrch of /state is '//i2s(st%nsrch)//', not 0 or 1'
    end if
    if (len_trim(r%msg) > 0) return
    ! every real dataset and attribute of /state: NaN or Inf in any of them is refused by name
    call need_finite(r, 'dataset /state/G', st%G)
    call need_finite(r, 'dataset /state/lam', st%lam)
    call need_finite(r, 'dataset /state/flam', st%flam)
    call need_finite(r, 'dataset /state/r_prev', st%r_prev)
    call need_finite(r, 'dataset /state/x_prev', st%x_prev)
    call need_finite(r, 'dataset /state/dX', st%dX)
    call need_finite(r, 'dataset /state/dR', st%dR)
    call need_finite(r, 'dataset /state/flam_v', st%flam_v)
    call need_finite(r, 'dataset /state/srch', st%srch)
    call need_finite(r, 'dataset /state/fsrch', st%fsrch)
    call need_finite(r, 'dataset /state/rw', st%rw)
    call need_finite(r, 'dataset /state/raw', st%raw)
    call need_finite(r, 'dataset /state/mu', st%eq_mult)
    call need_finite(r, 'attribute res_best of /state', [st%res_best])
    call need_finite(r, 'attribute crit of /state', [st%crit])
    call need_finite(r, 'attribute progress of /state', [st%progress])
    call need_finite(r, 'attribute best of /state', [st%best])
    call need_finite(r, 'attribute omega of /state', [st%omega])
    call need_finite(r, 'attribute wall of /state', [st%wall])
    if (len_trim(r%msg) > 0) return
    ! after the finite check: comparing a NaN traps in the checked build
    if (any(st%lam(:, 1) < 0.0_wp .and. .not. r%signed) .or. any(st%lam(:, 2) < 0.0_wp .and. .not. r%signed)) then
      r%msg = r%src//': dataset /state/lam holds negative contact forces'
      return
    end if
    ! history
    if (allocated(res%h_criterion)) deallocate (res%h_criterion, res%h_residual, res%h_wall, res%h_inner, &
                                                res%h_active)
    ! the history grows as the run goes on: room for what the checkpoint holds
    allocate (res%h_criterion(n), res%h_residual(n), res%h_wall(n), res%h_inner(n), res%h_active(n))
    res%h_criterion = 0.0_wp; res%h_residual = 0.0_wp; res%h_wall = 0.0_wp; res%h_inner = 0; res%h_active = 0
    if (allocated(res%lam)) deallocate (res%lam, res%lam_body, res%w, res%gap, res%obstacle)
    allocate (res%lam(m), res%lam_body(m, 2), res%w(m, 2), res%gap(m), res%obstacle(m, 2))
    res%lam = 0.0_wp; res%lam_body = 0.0_wp; res%w = 0.0_wp; res%gap = 0.0_wp; res%obstacle = st%G
    call read_history(r%fid, n, res, r%hs)
    if (r%hs%failed()) then
      r%msg = r%src//' has an incomplete history ('//r%hs%text()//')'
      return
    end if
    call need_finite(r, 'dataset /history/criterion', res%h_criterion(1:n))
    call need_finite(r, 'dataset /history/residual', res%h_residual(1:n))
    call need_finite(r, 'dataset /history/wall_s', res%h_wall(1:n))
    if (len_trim(r%msg) > 0) return
    if (any(res%h_inner(1:n) < 0) .or. any(res%h_active(1:n) < 0) .or. any(res%h_active(1:n) > m)) then
      r%msg = r%src//': dataset /history/inner or /history/active holds counts out of range'
      return
    end if
    res%nhist = n
    res%outer = n
    res%inner = st%inner
  end subroutine read_state

  !> r%msg naming the file and `obj` when `v` holds a NaN or an infinity.
  subroutine need_finite(r, obj, v)
    type(ckpt_reader_t), intent(inout) :: r
    character(len=*), intent(in) :: obj   !< 'dataset /state/mu', for the message
    real(wp), intent(in) :: v(..)
    integer :: bad
    if (len_trim(r%msg) > 0) return
    select rank (v)
    rank (1)
      bad = count(.not. ieee_is_finite(v))
    rank (2)
      bad = count(.not. ieee_is_finite(v))
    rank default
      bad = 0
    end select
    if (bad == 1) r%msg = r%src//': '//obj//' holds a value that is not finite (NaN or Inf)'
    if (bad > 1) r%msg = r%src//': '//obj//' holds '//i2s(bad)//' values that are not finite (NaN or Inf)'
  end subroutine need_finite

  !> The name of a type class, for messages.
  function class_name(c) result(t)
    integer, intent(in) :: c
    character(len=:), allocatable :: t
    select case (c)
    case (CLASS_INTEGER)
      t = 'integers'
    case (CLASS_REAL)
      t = 'real numbers'
    case (CLASS_STRING)
      t = 'a fixed-length string'
    case (CLASS_VSTRING)
      t = 'a variable-length string'
    case default
      t = 'data of another type'
    end select
  end function class_name

  !> A shape as h5py shows it (C order, the reverse of Fortran's): '(2, 16)', '()' for a
  !! scalar, 'n' for an extent that may be anything.
  function shape_text(d) result(t)
    integer(hsize_t), intent(in) :: d(:)
    character(len=:), allocatable :: t
    integer :: i
    t = '('
    do i = size(d), 1, -1
      if (d(i) < 0) then
        t = t//'n'
      else
        t = t//i2s(int(d(i)))
      end if
      if (i > 1) t = t//', '
    end do
    if (size(d) == 1) t = t//','
    t = t//')'
  end function shape_text

end module checkpoint
