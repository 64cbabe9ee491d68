!> Unit tests of the checkpoint of the outer Robin iteration (module checkpoint), on a run
!! state made up here (7 contact rows, two bodies, every field of robin_state_t set to its own
!! values, a -0.0 and a subnormal among them, a history of 5 iterations, a load history of
!! two converged steps), against that state itself:
!!  - written and read back, every field of the state, the counters and the history are
!!    bitwise equal (reals compared as their 64-bit patterns); the load history's steps too;
!!    no temporary file is left beside the checkpoint;
!!  - refused with an error (ERR_INPUT) whose message names the file and the cause, never a
!!    crash: a missing file, a text file, the file truncated to half, a quarter and 100
!!    bytes, its superblock overwritten, another deck's key, a mesh file whose content hash
!!    changed, a run with another number of contact rows (a shape), and states that are not a
!!    run's (NaN in a dataset, it beyond max_outer, a negative contact force);
!!  - every copy of the checkpoint with 8 of its bytes overwritten by 0xFF (at each multiple
!!    of 8: about 2300 copies, read by this program run again as `test_checkpoint --sweep
!!    FILE`) is refused with ERR_INPUT naming the file or read back, never a crash (with
!!    HDF5's default file format 12 of its 2501 copies crashed its parser, SIGSEGV);
!!  - the header's promise "a checkpoint that cannot be written whole leaves the previous
!!    one in place": a write whose temporary file cannot be created (a folder at its name)
!!    and a write whose rename fails (the final name a folder) each fail with ERR_IO naming
!!    the file, leave the earlier checkpoint byte for byte and no temporary file behind, and
!!    the earlier state reads back bitwise; the first failure is the one kept.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_checkpoint
  use, intrinsic :: iso_fortran_env, only: int64
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use kinds, only: wp
  use space, only: set_dimension
  use contact_types, only: robin_state_t, contact_result_t, state_init, alloc_result, recycle_size, STATUS_CONVERGED
  use results, only: step_result_t
  use checkpoint, only: h5_checkpointer_t, checkpoint_read, checkpoint_read_steps, checkpoint_file
  use files, only: temp_name
  use errors, only: error_t, ERR_INPUT, ERR_IO
  use strings, only: i2s
  use testing, only: report, test_summary, write_file, set_seed, urand, file_bytes, scratch_path, fresh_folder
  implicit none (type, external)

  !> the test's files: in its own build folder, beside the folder of the test programs (a
  !! release and a checked build's make check may run at once; a name starting test_ in that
  !! folder would be taken for a test)
  character(len=:), allocatable :: dir
  character(len=*), parameter :: KEY = 'deck inputs/x.nml: bodies 2, pairs 1, rows 7 (a made-up fingerprint)'
  character(len=*), parameter :: MESHES = '0123456789abcdef  /data/meshes/block.msh'
  integer, parameter :: m = 7, nbody = 2, depth = 5, maxout = 40, nh = 5
  type(robin_state_t) :: st, st2
  type(contact_result_t) :: res
  type(h5_checkpointer_t), target :: ck
  type(step_result_t), target :: done(2)
  character(len=:), allocatable :: file
  character(len=4096) :: arg

  call set_dimension(2)
  dir = scratch_path('test-checkpoint')
  ! `test_checkpoint --sweep FILE`: read corrupted copies of FILE (a child process: a crash
  ! ends it, not the test)
  if (command_argument_count() >= 2) then
    call get_command_argument(1, arg)
    if (arg == '--sweep') then
      call get_command_argument(2, arg)
      call sweep(trim(arg))
      stop 0
    end if
  end if
  call set_seed(4242)
  call fresh_folder(dir)
  file = checkpoint_file(dir//'/run.h5')
  call report(file == dir//'/run.h5.ckpt.h5', 'checkpoint_file: <result file>.ckpt.h5')

  call made_up_state(st, res)
  ck%file = file
  ck%key = KEY
  ck%meshes = MESHES
  call round_trip()
  call load_history()
  call refusals()
  call corrupted_copies()
  call failed_writes()
  call test_summary()

contains

  ! ---- the state ---------------------------------------------------------------------------

  !> Every field of a run's state and history set to values of its own (within what a run
  !! may hold: counters in range, forces >= 0, finite reals).
  subroutine made_up_state(s, r)
    type(robin_state_t), intent(out) :: s
    type(contact_result_t), intent(out) :: r
    integer :: kr, k
    call state_init(s, m, [(1.0e-4_wp*k, k=1, m)], nbody, 1)
    kr = recycle_size(m)
    s%it = nh
    s%inner = 1234
    s%nacc = 3
    s%stalled = 2
    s%it_best = 4
    s%res_best = urand(0.0_wp, 1.0_wp)*1.0e-7_wp
    s%crit = urand(0.0_wp, 1.0_wp)*1.0e-6_wp
    s%progress = 1.0_wp/3.0_wp
    s%best = tiny(1.0_wp)/16.0_wp          ! subnormal
    s%omega = -0.7_wp
    s%wall = 12.345_wp
    call fill(s%flam, 1.0e-3_wp)
    call fill2(s%G, 1.0e-4_wp)
    s%G(2, 1) = -0.0_wp                    ! the sign of a zero must survive
    call fill2(s%lam, 1.0e6_wp)
    s%lam = abs(s%lam)
    s%lam(3, 2) = 0.0_wp
    call fill(s%r_prev, 1.0_wp)
    call fill(s%x_prev, 1.0_wp)
    call fill2(s%dX, 1.0_wp)
    call fill2(s%dR, 1.0_wp)
    s%reuse = 1
    call fill2(s%flam_v, 1.0e-4_wp)
    s%nsrch = 1
    call fill2(s%srch, 1.0e3_wp)
    call fill2(s%fsrch, 1.0e-5_wp)
    s%settled = 1
    s%row_state = [-1, 0, 1, 2, 3, 15, 7]
    s%nrw(:, 1) = [3, 4]
    s%nrw(:, 2) = [kr, 1]
    s%newton = [0, -64]
    s%kept = [1, 0]
    call fill2(s%rw, 1.0_wp)
    call fill2(s%raw, 1.0e-3_wp)
    call fill2(s%eq_mult, 1.0e-2_wp)
    call alloc_result(r, m, 8, nbody)
    r%nhist = nh
    r%h_criterion(1:nh) = [1.0e-1_wp, 3.0e-3_wp, 2.0e-4_wp, 5.0e-6_wp, 7.0e-8_wp]
    r%h_residual(1:nh) = [2.0e-1_wp, 4.0e-3_wp, 1.0e-4_wp, 6.0e-6_wp, 8.0e-8_wp]
    r%h_wall(1:nh) = [0.5_wp, 1.5_wp, 2.25_wp, 3.0_wp, 12.345_wp]
    r%h_inner(1:nh) = [100, 400, 700, 1000, 1234]
    r%h_active(1:nh) = [7, 6, 6, 5, 5]
    r%inner_maxit_hits = 1
    r%eq_updates = 9
  end subroutine made_up_state

  subroutine fill(v, scale)
    real(wp), intent(out) :: v(:)
    real(wp), intent(in) :: scale
    integer :: i
    do i = 1, size(v)
      v(i) = scale*urand(-1.0_wp, 1.0_wp)
    end do
  end subroutine fill

  subroutine fill2(v, scale)
    real(wp), intent(out) :: v(:, :)
    real(wp), intent(in) :: scale
    integer :: j
    do j = 1, size(v, 2)
      call fill(v(:, j), scale)
    end do
  end subroutine fill2

  !> The 64-bit patterns of reals are equal (a -0.0 is not 0.0, a NaN equals its own bits).
  logical function same(a, b)
    real(wp), intent(in) :: a(:), b(:)
    same = size(a) == size(b)
    if (same) same = all(transfer(a, 0_int64, size(a)) == transfer(b, 0_int64, size(b)))
  end function same

  logical function same2(a, b)
    real(wp), intent(in) :: a(:, :), b(:, :)
    same2 = all(shape(a) == shape(b))
    if (same2) same2 = same(reshape(a, [size(a)]), reshape(b, [size(b)]))
  end function same2

  !> Every field of two states bitwise equal.
  logical function states_equal(a, b) result(ok)
    type(robin_state_t), intent(in) :: a, b
    ok = a%it == b%it .and. a%inner == b%inner .and. a%nacc == b%nacc .and. a%stalled == b%stalled .and. &
         a%it_best == b%it_best .and. a%reuse == b%reuse .and. a%nsrch == b%nsrch .and. a%settled == b%settled
    ok = ok .and. same([a%res_best, a%crit, a%progress, a%best, a%omega, a%wall], &
                       [b%res_best, b%crit, b%progress, b%best, b%omega, b%wall])
    ok = ok .and. same(a%flam, b%flam) .and. same2(a%G, b%G) .and. same2(a%lam, b%lam) .and. &
         same(a%r_prev, b%r_prev) .and. same(a%x_prev, b%x_prev) .and. same2(a%dX, b%dX) .and. &
         same2(a%dR, b%dR) .and. same2(a%flam_v, b%flam_v) .and. same2(a%srch, b%srch) .and. &
         same2(a%fsrch, b%fsrch) .and. same2(a%rw, b%rw) .and. same2(a%raw, b%raw) .and. same2(a%eq_mult, b%eq_mult)
    ok = ok .and. all(shape(a%nrw) == shape(b%nrw)) .and. size(a%row_state) == size(b%row_state) .and. &
         size(a%newton) == size(b%newton) .and. size(a%kept) == size(b%kept)
    if (ok) ok = all(a%nrw == b%nrw) .and. all(a%row_state == b%row_state) .and. all(a%newton == b%newton) .and. &
                 all(a%kept == b%kept)
  end function states_equal


  !> Write bytes to path (replacing it).
  subroutine put_bytes(path, b)
    character(len=*), intent(in) :: path, b
    integer :: u
    open (newunit=u, file=path, access='stream', form='unformatted', status='replace', action='write')
    write (u) b
    close (u)
  end subroutine put_bytes

  !> No temporary file (*.tmp) left in the test's folder.
  logical function no_temporaries()
    integer :: r
    call execute_command_line('ls -A '//dir//' | grep -q "\.tmp$"', exitstat=r)
    no_temporaries = r /= 0
  end function no_temporaries

  ! ---- write and read back ------------------------------------------------------------------

  subroutine round_trip()
    type(contact_result_t) :: res2
    type(error_t) :: err
    call ck%save(st, res)
    call report(.not. ck%err%failed() .and. len(file_bytes(file)) > 0 .and. no_temporaries(), &
                'save: the checkpoint written, no temporary file left')
    call checkpoint_read(file, KEY, MESHES, m, nbody, depth, maxout, st2, res2, err)
    call report(.not. err%failed(), 'read: accepted by the run it was made for')
    if (err%failed()) then
      write (*, '(a)') '      '//err%text()
      return
    end if
    call report(states_equal(st, st2), 'read: every field of the outer state bitwise equal (-0.0 and a subnormal too)')
    call report(res2%nhist == nh .and. res2%outer == nh .and. res2%inner == st%inner .and. &
                res2%inner_maxit_hits == res%inner_maxit_hits .and. res2%eq_updates == res%eq_updates, &
                'read: the counters (outer, inner, inner_maxit_hits, equality_updates)')
    call report(same(res2%h_criterion(1:nh), res%h_criterion(1:nh)) .and. same(res2%h_residual(1:nh), &
                res%h_residual(1:nh)) .and. same(res2%h_wall(1:nh), res%h_wall(1:nh)) .and. &
                all(res2%h_inner(1:nh) == res%h_inner(1:nh)) .and. all(res2%h_active(1:nh) == res%h_active(1:nh)), &
                'read: the history bitwise equal')
    call report(same2(res2%obstacle, st%G), 'read: the result''s obstacles are the state''s')
  end subroutine round_trip

  !> A run of load steps: the step being solved and the converged results of the steps before
  !! it come back bitwise.
  subroutine load_history()
    type(h5_checkpointer_t) :: cl
    type(contact_result_t), allocatable :: back(:)
    type(contact_result_t) :: res2
    type(error_t) :: err
    integer :: k, step
    logical :: ok
    do k = 1, 2
      call alloc_result(done(k)%res, m, 1, nbody)
      done(k)%res%status = STATUS_CONVERGED
      done(k)%res%outer = 10*k
      done(k)%res%inner = 100*k
      done(k)%res%residual = 1.0e-9_wp/k
      call fill(done(k)%res%lam, 1.0e5_wp)
      done(k)%res%lam = abs(done(k)%res%lam)
      call fill2(done(k)%res%lam_body, 1.0e5_wp)
      call fill2(done(k)%res%w, 1.0e-4_wp)
      call fill(done(k)%res%gap, 1.0e-6_wp)
      call fill2(done(k)%res%obstacle, 1.0e-4_wp)
      call fill2(done(k)%res%rigid, 1.0e-3_wp)
    end do
    cl%file = dir//'/steps.h5.ckpt.h5'
    cl%key = KEY
    cl%step = 3
    cl%done => done
    call cl%save(st, res)
    call checkpoint_read_steps(cl%file, m, nbody, 4, step, back, err)
    ok = .not. err%failed() .and. step == 3 .and. size(back) == 2
    if (ok) then
      do k = 1, 2
        ok = ok .and. back(k)%status == STATUS_CONVERGED .and. back(k)%outer == 10*k .and. back(k)%inner == 100*k .and. &
             same([back(k)%residual], [done(k)%res%residual]) .and. same(back(k)%lam, done(k)%res%lam) .and. &
             same2(back(k)%lam_body, done(k)%res%lam_body) .and. same2(back(k)%w, done(k)%res%w) .and. &
             same(back(k)%gap, done(k)%res%gap) .and. same2(back(k)%obstacle, done(k)%res%obstacle) .and. &
             same2(back(k)%rigid, done(k)%res%rigid)
      end do
    end if
    call report(ok, 'load history: the step resumed and the two converged steps before it bitwise equal')
    call checkpoint_read(cl%file, KEY, '', m, nbody, depth, maxout, st2, res2, err)
    call report(.not. err%failed() .and. states_equal(st, st2), 'load history: the state beside it reads back too')
    call checkpoint_read_steps(cl%file, m, nbody, 2, step, back, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), 'outside 1 .. 2') > 0, &
                'load history: a step beyond this deck''s load steps refused: '//err%text())
    call checkpoint_read_steps(file, m, nbody, 4, step, back, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), 'no group /load_history') > 0, &
                'load history: a checkpoint of a run of one step refused by a run of four: '//err%text())
  end subroutine load_history

  ! ---- refusals -------------------------------------------------------------------------------

  !> Read `path` as this run's checkpoint (or with another key, meshes or row count) and check
  !! that it is refused with ERR_INPUT, naming the file and containing `cause`.
  subroutine refused(path, cause, what, key_, meshes_, m_)
    character(len=*), intent(in) :: path, cause, what
    character(len=*), intent(in), optional :: key_, meshes_
    integer, intent(in), optional :: m_
    type(robin_state_t) :: s
    type(contact_result_t) :: r
    type(error_t) :: err
    character(len=:), allocatable :: k, ms
    integer :: mm
    k = KEY
    if (present(key_)) k = key_
    ms = MESHES
    if (present(meshes_)) ms = meshes_
    mm = m
    if (present(m_)) mm = m_
    call checkpoint_read(path, k, ms, mm, nbody, depth, maxout, s, r, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), 'restart file '//path) > 0, &
                what//' (ERR_INPUT, the message names the file)')
    call report(index(err%text(), cause) > 0, what//': "'//err%text()//'"')
  end subroutine refused

  subroutine refusals()
    type(robin_state_t) :: bad
    type(contact_result_t) :: rbad
    type(h5_checkpointer_t) :: cb
    character(len=:), allocatable :: b, p
    call refused(dir//'/none.ckpt.h5', 'does not exist', 'refused: a missing file')
    call write_file(dir//'/text.ckpt.h5', [character(len=40) :: '&solver tol=1e-8 /', 'not a checkpoint'])
    call refused(dir//'/text.ckpt.h5', 'is not an HDF5 file', 'refused: a text file')
    b = file_bytes(file)
    p = dir//'/cut.ckpt.h5'
    call put_bytes(p, b(1:len(b)/2))
    call refused(p, 'restart file', 'refused: the checkpoint truncated to half')
    call put_bytes(p, b(1:len(b)/4))
    call refused(p, 'restart file', 'refused: the checkpoint truncated to a quarter')
    call put_bytes(p, b(1:100))
    call refused(p, 'is not an HDF5 file', 'refused: the checkpoint truncated to 100 bytes')
    call put_bytes(p, repeat('x', 8)//b(9:))
    call refused(p, 'is not an HDF5 file', 'refused: the checkpoint''s superblock signature overwritten')
    call refused(file, 'made from a different deck', 'refused: another deck''s checkpoint', key_=KEY//' changed')
    call refused(file, 'mesh file /data/meshes/block.msh changed since the checkpoint was written', &
                 'refused: a mesh file whose content changed', meshes_='fedcba9876543210  /data/meshes/block.msh')
    call refused(file, 'this deck has 8 contact nodes', 'refused: a run with another number of contact rows', m_=8)
    ! states no run leaves: written by the module itself, refused when read
    cb%file = dir//'/bad.ckpt.h5'
    cb%key = KEY
    cb%meshes = MESHES
    bad = st
    bad%lam(4, 1) = ieee_value(1.0_wp, ieee_quiet_nan)
    call cb%save(bad, res)
    call refused(cb%file, 'dataset /state/lam holds a value that is not finite', 'refused: NaN in a force')
    bad = st
    bad%it = maxout + 1
    rbad = res
    call cb%save(bad, rbad)
    call refused(cb%file, 'attribute it of /state is 41, outside 1 .. max_outer = 40', 'refused: it beyond max_outer')
    bad = st
    bad%lam(2, 2) = -1.0_wp
    call cb%save(bad, res)
    call refused(cb%file, 'negative contact forces', 'refused: a negative contact force')
  end subroutine refusals

  ! ---- corrupted copies ------------------------------------------------------------------------

  !> The child: each copy of `path` with bytes k..k+7 set to 0xFF (k = 1, 9, 17, ...) read as
  !! this run's checkpoint; `at k` printed (and flushed) before each read, so that a crash
  !! names its copy; last line `sweep: N copies, R refused, A read, B bad messages`.
  subroutine sweep(path)
    use, intrinsic :: iso_fortran_env, only: output_unit
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: b, c, copy
    type(robin_state_t) :: s
    type(contact_result_t) :: r
    type(error_t) :: err
    integer :: k, n, nref, nread, nbad
    b = file_bytes(path)
    copy = path//'.corrupt'
    nref = 0
    nread = 0
    nbad = 0
    n = 0
    do k = 1, len(b) - 7, 8
      c = b
      c(k:k + 7) = repeat(char(255), 8)
      call put_bytes(copy, c)
      write (output_unit, '(a,i0)') 'at ', k
      flush (output_unit)
      call checkpoint_read(copy, KEY, MESHES, m, nbody, depth, maxout, s, r, err)
      n = n + 1
      if (err%failed()) then
        nref = nref + 1
        if (err%category /= ERR_INPUT .or. index(err%text(), 'restart file '//copy) == 0) then
          nbad = nbad + 1
          write (output_unit, '(a)') 'bad message: '//err%text()
        end if
      else
        nread = nread + 1
      end if
    end do
    write (output_unit, '(a,i0,a,i0,a,i0,a,i0,a)') 'sweep: ', n, ' copies, ', nref, ' refused, ', nread, ' read, ', &
      nbad, ' bad messages'
  end subroutine sweep

  !> Run the sweep in a child process on this run's checkpoint: no copy crashes the reader.
  subroutine corrupted_copies()
    character(len=4096) :: self
    character(len=:), allocatable :: out, last, text
    integer :: r, n, nref, nread, nbad, i
    call get_command_argument(0, self)
    out = dir//'/sweep.log'
    call execute_command_line(trim(self)//' --sweep '//file//' > '//out//' 2>&1', exitstat=r)
    text = achar(10)//file_bytes(out)
    i = index(text, 'sweep: ')
    n = -1
    nbad = -1
    if (i > 0) then
      last = text(i:)
      if (index(last, achar(10)) > 0) last = last(1:index(last, achar(10)) - 1)
      call counts(last, n, nref, nread, nbad)
      call report(r == 0 .and. n > 1000 .and. nref > 0 .and. nbad == 0, &
                  'corrupted copies: each refused naming the file (ERR_INPUT) or read, none crashed ('//last//')')
    else
      i = index(text, achar(10)//'at ', back=.true.)
      last = ''
      if (i > 0) last = text(i + 1:min(len(text), i + 12))
      if (index(last, achar(10)) > 0) last = last(1:index(last, achar(10)) - 1)
      call report(.false., 'corrupted copies: the reader crashed on the copy '//last//' (exit '//i2s(r)//'; see '// &
                  out//')')
    end if
  end subroutine corrupted_copies

  !> The four counts of the sweep's last line.
  subroutine counts(line, n, nref, nread, nbad)
    character(len=*), intent(in) :: line
    integer, intent(out) :: n, nref, nread, nbad
    character(len=len(line)) :: t
    integer :: ios
    t = line
    ! 'sweep: N copies, R refused, A read, B bad messages' -> the numbers
    t = t(8:)
    t = replace_all(replace_all(replace_all(replace_all(t, ' copies,', ' '), ' refused,', ' '), ' read,', ' '), &
                    ' bad messages', ' ')
    read (t, *, iostat=ios) n, nref, nread, nbad
    if (ios /= 0) nbad = -1
  end subroutine counts

  function replace_all(s, a, b) result(t)
    character(len=*), intent(in) :: s, a, b
    character(len=:), allocatable :: t
    integer :: i
    t = s
    do
      i = index(t, a)
      if (i == 0) exit
      t = t(1:i - 1)//b//t(i + len(a):)
    end do
  end function replace_all

  ! ---- failed writes -------------------------------------------------------------------------

  !> A checkpoint that cannot be written whole leaves the previous one in place.
  subroutine failed_writes()
    type(robin_state_t) :: later
    type(contact_result_t) :: res2
    type(error_t) :: err
    character(len=:), allocatable :: before, t, next_tmp, first
    integer :: n, dot, r
    before = file_bytes(file)
    ! the temporary name of the next write: temp_name's counter is this process's
    t = temp_name(file)
    dot = index(t(1:len(t) - 4), '.', back=.true.)
    read (t(dot + 1:len(t) - 4), *) n
    next_tmp = t(1:dot)//i2s(n + 1)//'.tmp'
    call execute_command_line('mkdir '//next_tmp, exitstat=r)
    later = st
    later%it = nh
    later%G = 2.0_wp*st%G
    call ck%save(later, res)
    call report(ck%err%category == ERR_IO .and. index(ck%err%text(), file) > 0 .and. &
                index(ck%err%text(), 'the previous one, if any, is kept') > 0, &
                'failed write (its temporary file cannot be made): ERR_IO naming the file: '//ck%err%text())
    call report(file_bytes(file) == before, 'failed write: the earlier checkpoint byte for byte')
    call checkpoint_read(file, KEY, MESHES, m, nbody, depth, maxout, st2, res2, err)
    call report(.not. err%failed() .and. states_equal(st, st2), 'failed write: the earlier state reads back bitwise')
    call execute_command_line('rmdir '//next_tmp, exitstat=r)
    first = ck%err%text()
    ! the final name a folder: the rename fails, the temporary file is removed
    ck%file = dir//'/folder.ckpt.h5'
    call execute_command_line('mkdir -p '//ck%file//'/kept', exitstat=r)
    call ck%save(later, res)
    call report(ck%err%text() == first, 'failed writes: the first failure is the one kept')
    call report(no_temporaries(), 'failed write (the rename fails): no temporary file left')
    call execute_command_line('test -d '//ck%file//'/kept', exitstat=r)
    call report(r == 0, 'failed write (the rename fails): what was at the final name is kept')
    ck%err = error_t()
    call ck%save(later, res)
    call report(ck%err%category == ERR_IO .and. index(ck%err%text(), 'failed to rename') > 0, &
                'failed write (the rename fails): ERR_IO: '//ck%err%text())
    ! and a good write after the failures replaces the checkpoint
    ck%file = file
    ck%err = error_t()
    call ck%save(later, res)
    call checkpoint_read(file, KEY, MESHES, m, nbody, depth, maxout, st2, res2, err)
    call report(.not. ck%err%failed() .and. .not. err%failed() .and. states_equal(later, st2), &
                'a good write after them replaces the checkpoint')
  end subroutine failed_writes


end program test_checkpoint
