!> File-system helpers of the output stage: temporary names, atomic rename, committing a
!! set of files together, parent folders, removal and whole-file text output.
!!
!! Result and checkpoint files are written under a temporary name of their own run
!! (`temp_name`: `<file>.<host>.<pid>.<n>.tmp`, so two runs writing the same result never
!! share one) and renamed to their final names only when complete; the rename is the
!! only step runs share. A result made of several files is committed by `commit_files`:
!! under a lock of the folder, all final names are checked first, the files already
!! there are kept aside, and any failure puts them back, so readers see either all the
!! old files or all the new ones.
module files
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_ptr, c_long_long, c_long
  use errors, only: error_t, ERR_INPUT, ERR_IO
  use strings, only: i2s
  implicit none (type, external)
  private

  public :: temp_name, run_id, replace_suffix, base_name, dir_name, ensure_parent_dir, atomic_rename, &
            remove_file, write_text, commit_files, special_file, data_open, data_write, data_close, &
            check_new_files

  interface
    integer(c_int) function c_rename(old, new) bind(c, name='rename')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_rename
    integer(c_int) function c_link(old, new) bind(c, name='link')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_link
    integer(c_int) function c_mkdir(path, mode) bind(c, name='mkdir')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int), value :: mode
    end function c_mkdir
    integer(c_int) function c_unlink(path) bind(c, name='unlink')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: path(*)
    end function c_unlink
    integer(c_int) function rc_run_token(buf, n) bind(c, name='rc_run_token')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: n
    end function rc_run_token
    integer(c_int) function rc_lock_dir(dir) bind(c, name='rc_lock_dir')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: dir(*)
    end function rc_lock_dir
    subroutine rc_unlock_dir(fd) bind(c, name='rc_unlock_dir')
      import :: c_int
      implicit none (type, external)
      integer(c_int), value :: fd
    end subroutine rc_unlock_dir
    integer(c_int) function rc_path_kind(path) bind(c, name='rc_path_kind')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: path(*)
    end function rc_path_kind
    integer(c_int) function rc_file_kind(path) bind(c, name='rc_file_kind')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: path(*)
    end function rc_file_kind
    integer(c_long) function rc_name_max(dir) bind(c, name='rc_name_max')
      import :: c_long, c_char
      character(kind=c_char), intent(in) :: dir(*)
    end function rc_name_max
    integer(c_int) function rc_dir_writable(dir) bind(c, name='rc_dir_writable')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: dir(*)
    end function rc_dir_writable
    integer(c_int) function rc_open_data(path) bind(c, name='rc_open_data')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: path(*)
    end function rc_open_data
    integer(c_int) function rc_write_at(fd, buf, n, offset) bind(c, name='rc_write_at')
      import :: c_int, c_ptr, c_long_long
      integer(c_int), value :: fd
      type(c_ptr), value :: buf
      integer(c_long_long), value :: n, offset
    end function rc_write_at
    integer(c_int) function rc_close_data(fd) bind(c, name='rc_close_data')
      import :: c_int
      integer(c_int), value :: fd
    end function rc_close_data
    integer(c_int) function rc_error_text(e, buf, n) bind(c, name='rc_error_text')
      import :: c_int, c_char
      integer(c_int), value :: e, n
      character(kind=c_char), intent(out) :: buf(*)
    end function rc_error_text
  end interface

  integer, save :: counter = 0                       ! unique names made by this process
  character(len=:), allocatable, save :: token       ! '<host>.<pid>'
  character(len=:), allocatable, save :: id          ! token and start time

  integer, parameter :: PATH_MAX = 4096   ! Linux's longest path, its terminating NUL included
  integer, parameter :: NAME_MAX = 255    ! the longest name of one entry where pathconf does not say
  integer, parameter :: KEPT_NONE = 0     ! no earlier file at the final name
  integer, parameter :: KEPT_LINK = 1     ! earlier file kept aside as a hard link (still in place)
  integer, parameter :: KEPT_MOVED = 2    ! earlier file renamed aside (final name free)

contains

  !> A temporary name for `file`, unique to this run and to this call:
  !! `<file>.<host>.<pid>.<n>.tmp` with n counting the names this process has made (1, 2,
  !! ...), in the same folder so that the final rename is atomic.
  function temp_name(file) result(t)
    character(len=*), intent(in) :: file   !< final path
    character(len=:), allocatable :: t
    t = unique_name(file, '.tmp')
  end function temp_name

  !> The identity of this run, `<host>.<pid>.<yyyymmddThhmmss>` (fixed at the first call):
  !! stored in the result file and in its XDMF files, so that they can be matched.
  function run_id() result(r)
    character(len=:), allocatable :: r
    character(len=8) :: date
    character(len=10) :: time
    if (.not. allocated(id)) then
      call date_and_time(date, time)
      id = run_token()//'.'//date//'T'//time(1:6)
    end if
    r = id
  end function run_id

  !> Whether files can be created at `names` (final paths, one folder), checked before any
  !! work so that a name the file system cannot hold is bad input, not a failure after the
  !! solve: each name and the longest temporary or kept-aside name made of it
  !! (`<name>.<host>.<pid>.<n>.tmp`, n up to 10 digits) within PATH_MAX (4096 bytes with the
  !! terminating NUL), each of their components within the file system's NAME_MAX (pathconf
  !! of the nearest existing folder; 255 where it does not say), and that folder a folder
  !! this process may write into (the missing ones below it are created). err (ERR_INPUT)
  !! names the file, its length and the limit.
  subroutine check_new_files(names, err)
    character(len=*), intent(in) :: names(:)   !< the final paths
    type(error_t), intent(out) :: err          !< the first name that cannot be made
    character(len=:), allocatable :: dir, p, longest
    integer :: k, i, j, n, kind, extra
    integer(c_long) :: nmax

    if (size(names) == 0) return
    extra = len('.'//run_token()//'.'//'4294967295'//'.tmp')
    ! the nearest existing folder of the first name (all are in one folder)
    dir = dir_name(trim(names(1)))
    do   ! (a path through a regular file cannot be inspected: ENOTDIR; its parent says why)
      kind = rc_file_kind(dir//c_null_char)
      if (kind > 0) exit
      p = dir_name(dir)
      if (p == dir) exit
      dir = p
    end do
    if (kind == 1 .or. kind == 3) then
      call err%set(ERR_INPUT, 'output file '//trim(names(1))//': '//dir//' is not a folder, so the file '// &
                   'cannot be made there')
      return
    else if (kind /= 2) then
      call err%set(ERR_INPUT, 'output file '//trim(names(1))//': cannot inspect the folder '//dir)
      return
    end if
    if (rc_dir_writable(dir//c_null_char) /= 1) then
      call err%set(ERR_INPUT, 'output file '//trim(names(1))//': the folder '//dir//' is not writable by '// &
                   'this process')
      return
    end if
    nmax = rc_name_max(dir//c_null_char)
    if (nmax <= 0) nmax = NAME_MAX
    do k = 1, size(names)
      n = len_trim(names(k))
      if (n + extra + 1 > PATH_MAX) then
        call err%set(ERR_INPUT, 'output file '//trim(names(k))//': its path is '//i2s(n)//' bytes, '// &
          i2s(n + extra)//' with the suffix of its temporary name (.<host>.<pid>.<n>.tmp), over the system''s '// &
          'limit of '//i2s(PATH_MAX - 1)//' bytes for a path (PATH_MAX); use a shorter &output file')
        return
      end if
      ! each component; the last one with the temporary name's suffix
      i = 1
      do while (i <= n)
        j = index(names(k)(i:n), '/')
        if (j == 0) then
          j = n + 1
        else
          j = i + j - 1
        end if
        if (j == n + 1) then
          longest = names(k)(i:n)
          if (len(longest) + extra > nmax) then
            call err%set(ERR_INPUT, 'output file '//trim(names(k))//': its name '''//longest//''' is '// &
              i2s(len(longest))//' bytes, '//i2s(len(longest) + extra)//' with the suffix of its temporary '// &
              'name (.<host>.<pid>.<n>.tmp), over the file system''s limit of '//i2s(int(nmax))// &
              ' bytes for one name (NAME_MAX) in '//dir//'; use a shorter &output file')
            return
          end if
        else if (j - i > nmax) then
          call err%set(ERR_INPUT, 'output file '//trim(names(k))//': its folder name '''//names(k)(i:j - 1)// &
            ''' is '//i2s(j - i)//' bytes, over the file system''s limit of '//i2s(int(nmax))// &
            ' bytes for one name (NAME_MAX) in '//dir//'; use a shorter &output file')
          return
        end if
        i = j + 1
      end do
    end do
  end subroutine check_new_files

  !> `<file>.<host>.<pid>.<n><suffix>` with the next n of this process.
  function unique_name(file, suffix) result(t)
    character(len=*), intent(in) :: file, suffix
    character(len=:), allocatable :: t
    character(len=16) :: n
    integer :: k
    !$omp critical (files_counter)
    counter = counter + 1
    k = counter
    !$omp end critical (files_counter)
    write (n, '(i0)') k
    t = trim(file)//'.'//run_token()//'.'//trim(n)//suffix
  end function unique_name

  !> '<host>.<pid>', the host name reduced to [A-Za-z0-9_-].
  function run_token() result(t)
    character(len=:), allocatable :: t
    character(kind=c_char) :: buf(128)
    integer :: n
    if (.not. allocated(token)) then
      n = rc_run_token(buf, int(size(buf), c_int))
      token = transfer(buf(1:n), repeat(' ', n))
    end if
    t = token
  end function run_token

  !> `file` with its ending `old` replaced by `new` (`new` appended when it does not end
  !! so): replace_suffix('a/x.h5', '.h5', '.xdmf') is 'a/x.xdmf'.
  function replace_suffix(file, old, new) result(p)
    character(len=*), intent(in) :: file   !< a path
    character(len=*), intent(in) :: old    !< ending to replace, such as '.h5'
    character(len=*), intent(in) :: new    !< its replacement
    character(len=:), allocatable :: p
    integer :: l
    l = len_trim(file)
    p = file(1:l)//new
    if (l > len(old)) then
      if (file(l - len(old) + 1:l) == old) p = file(1:l - len(old))//new
    end if
  end function replace_suffix

  !> The last component of a path: base_name('a/b/x.h5') is 'x.h5'.
  function base_name(file) result(b)
    character(len=*), intent(in) :: file   !< a path
    character(len=:), allocatable :: b
    integer :: i
    i = index(trim(file), '/', back=.true.)
    b = trim(file(i + 1:))
  end function base_name

  !> The folder of a path: dir_name('a/b/x.h5') is 'a/b', dir_name('x.h5') is '.',
  !! dir_name('/x.h5') is '/'.
  function dir_name(file) result(d)
    character(len=*), intent(in) :: file   !< a path
    character(len=:), allocatable :: d
    integer :: i
    i = index(trim(file), '/', back=.true.)
    if (i == 0) then
      d = '.'
    else if (i == 1) then
      d = '/'
    else
      d = file(1:i - 1)
    end if
  end function dir_name

  !> Create the folders leading to `file` (like mkdir -p of its parent); existing ones are
  !! left alone, failures show when the file itself is created.
  subroutine ensure_parent_dir(file)
    character(len=*), intent(in) :: file  !< a file path
    integer :: i, rc
    do i = 2, len_trim(file)
      if (file(i:i) == '/') rc = c_mkdir(file(1:i - 1)//c_null_char, int(o'755', c_int))
    end do
  end subroutine ensure_parent_dir

  !> rename(2): atomic within one file system; replaces `new`. err (ERR_IO) on failure.
  subroutine atomic_rename(old, new, err)
    character(len=*), intent(in) :: old   !< temporary name
    character(len=*), intent(in) :: new   !< final name
    type(error_t), intent(out) :: err     !< ERR_IO: the rename failed, naming both
    if (c_rename(trim(old)//c_null_char, trim(new)//c_null_char) /= 0) &
      call err%set(ERR_IO, 'cannot rename '//trim(old)//' to '//trim(new))
  end subroutine atomic_rename

  !> True when `path` names something that exists and is not a regular file (after
  !! symbolic links): a folder, FIFO, device or socket. Opening a FIFO to read waits for a
  !! writer, so a reader checks its input file here first.
  logical function special_file(path)
    character(len=*), intent(in) :: path   !< the file
    integer :: kind
    kind = rc_file_kind(path//c_null_char)
    special_file = kind == 2 .or. kind == 3
  end function special_file

  !> unlink(2) `path` if it exists (a symbolic link is removed, not its target).
  subroutine remove_file(path)
    character(len=*), intent(in) :: path  !< file to remove
    integer :: rc
    rc = c_unlink(trim(path)//c_null_char)
  end subroutine remove_file

  !> Rename the complete files tmp(k) to final(k), k = 1, 2, ... in this order, all or
  !! nothing; the final names must be in one folder. Under an exclusive lock of that
  !! folder (concurrent commits into it wait for each other): (1) every final name must
  !! be free or hold a file (not a folder or a device) and the folder must be writable;
  !! (2) the files already at the final names are kept aside (a hard link, or a rename
  !! where links are not supported); (3) the renames; (4) the kept files are removed.
  !! When a step fails, what this call renamed into place is undone, the kept files are
  !! put back, the temporary files are removed, and err (ERR_IO) says what failed.
  !! With `stale_prefix`, once all are renamed and still under the lock, the numbered files
  !! `<stale_prefix(i)><k><stale_suffix>` for k = stale_first(i), stale_first(i) + 1, ...
  !! up to the first that does not exist (an earlier, larger set's own files, which the
  !! new set lacks) are removed; `removed` counts them. A failed commit removes none.
  subroutine commit_files(tmp, final, err, stale_prefix, stale_first, stale_suffix, removed)
    character(len=*), intent(in) :: tmp(:)                 !< complete files, temporary names
    character(len=*), intent(in) :: final(:)               !< their final names
    type(error_t), intent(out) :: err                      !< ERR_IO: what failed (none renamed)
    character(len=*), intent(in), optional :: stale_prefix(:)   !< numbered names of an earlier set: the part before k
    integer, intent(in), optional :: stale_first(:)        !< the first k each prefix's new set lacks
    character(len=*), intent(in), optional :: stale_suffix !< the part after k
    integer, intent(out), optional :: removed              !< stale files removed
    character(len=len(final) + 160) :: bak(size(final))
    integer :: kept(size(final)), k, j, fd, kind
    character(len=:), allocatable :: dir, stale, msg
    logical :: ok
    type(error_t) :: step

    ok = .false.
    msg = ''
    kept = KEPT_NONE
    dir = dir_name(final(1))
    fd = rc_lock_dir(dir//c_null_char)
    ! 1. every final name can be replaced
    if (rc_dir_writable(dir//c_null_char) /= 1) msg = 'the folder '//dir//' is not writable'
    do k = 1, size(final)
      if (len(msg) > 0) exit
      kind = rc_path_kind(trim(final(k))//c_null_char)
      if (kind == 2) then
        msg = trim(final(k))//' is a folder'
      else if (kind == 3) then
        msg = trim(final(k))//' is not a regular file'
      else if (kind < 0) then
        msg = 'cannot inspect '//trim(final(k))
      end if
    end do
    if (len(msg) > 0) then
      msg = msg//'; nothing was replaced'
      call finish()
      return
    end if
    ! 2. keep the earlier files aside
    do k = 1, size(final)
      if (rc_path_kind(trim(final(k))//c_null_char) == 0) cycle
      bak(k) = unique_name(final(k), '.bak')
      if (c_link(trim(final(k))//c_null_char, trim(bak(k))//c_null_char) == 0) then
        kept(k) = KEPT_LINK
      else if (c_rename(trim(final(k))//c_null_char, trim(bak(k))//c_null_char) == 0) then
        kept(k) = KEPT_MOVED
      else
        msg = 'cannot keep the earlier '//trim(final(k))//' aside'//restore(1, size(final), .false.)// &
              '; nothing was replaced'
        call finish()
        return
      end if
    end do
    ! 3. the renames
    do k = 1, size(final)
      call atomic_rename(tmp(k), final(k), step)
      if (step%failed()) then
        msg = 'cannot rename '//trim(tmp(k))//' to '//trim(final(k))//restore(1, k - 1, .true.)// &
              restore(k, size(final), .false.)
        call finish()
        return
      end if
    end do
    ! 4. the earlier files are no longer needed
    do k = 1, size(final)
      if (kept(k) /= KEPT_NONE) call remove_file(bak(k))
    end do
    ok = .true.
    ! 5. an earlier, larger set's numbered files the new set does not have
    if (present(removed)) removed = 0
    if (present(stale_prefix) .and. present(stale_first) .and. present(stale_suffix)) then
      do j = 1, size(stale_prefix)
        k = stale_first(j)
        do
          stale = trim(stale_prefix(j))//i2s(k)//stale_suffix
          if (rc_path_kind(stale//c_null_char) /= 1) exit
          if (c_unlink(stale//c_null_char) /= 0) exit
          if (present(removed)) removed = removed + 1
          k = k + 1
        end do
      end do
    end if
    call finish()

  contains

    !> Put back the earlier files of final(k1:k2): renamed = .true. when this call has
    !! renamed a new file into their place. Returns '' or a note of what could not be put back.
    function restore(k1, k2, renamed) result(note)
      integer, intent(in) :: k1, k2
      logical, intent(in) :: renamed
      character(len=:), allocatable :: note
      integer :: i
      logical :: back
      type(error_t) :: moved
      note = ''
      do i = k1, k2
        back = .true.
        select case (kept(i))
        case (KEPT_NONE)
          if (renamed) call remove_file(final(i))
        case (KEPT_LINK)
          if (renamed) then
            call atomic_rename(bak(i), final(i), moved)
            back = .not. moved%failed()
          else
            call remove_file(bak(i))
          end if
        case (KEPT_MOVED)
          call atomic_rename(bak(i), final(i), moved)
          back = .not. moved%failed()
        end select
        if (.not. back) note = note//'; the earlier '//trim(final(i))//' could not be put back: it is '//trim(bak(i))
        kept(i) = KEPT_NONE
      end do
      if (len(note) == 0 .and. renamed) note = '; the earlier files were put back'
    end function restore

    subroutine finish()
      if (.not. ok) then
        do j = 1, size(tmp)
          call remove_file(tmp(j))
        end do
        call err%set(ERR_IO, msg)
      end if
      call rc_unlock_dir(fd)
    end subroutine finish

  end subroutine commit_files

  !> Write `text` as the whole content of `path` (replaced). err (ERR_IO) when the file
  !! cannot be created, written or closed (a full disk shows at the latest on close).
  subroutine write_text(path, text, err)
    character(len=*), intent(in) :: path   !< file to write
    character(len=*), intent(in) :: text   !< its content, lines ended by new-line characters
    type(error_t), intent(out) :: err      !< ERR_IO: the file could not be written, naming it
    integer :: u, ios, ios_close
    open (newunit=u, file=path, status='replace', access='stream', form='unformatted', &
          action='write', iostat=ios)
    if (ios /= 0) then
      call err%set(ERR_IO, 'cannot create '//trim(path))
      return
    end if
    write (u, iostat=ios) text
    close (u, iostat=ios_close)
    if (ios /= 0 .or. ios_close /= 0) call err%set(ERR_IO, 'cannot write '//trim(path))
  end subroutine write_text

  !> Open the existing file `path` for writing at given offsets (`data_write`), without
  !! truncating it; fd = -1 and err (ERR_IO, naming the file, with the system's reason) on
  !! failure.
  subroutine data_open(path, fd, err)
    character(len=*), intent(in) :: path      !< the file
    integer, intent(out) :: fd                !< its descriptor, -1 on failure
    type(error_t), intent(out) :: err         !< ERR_IO: the file cannot be opened
    fd = rc_open_data(trim(path)//c_null_char)
    if (fd < 0) then
      call set_system_error(err, trim(path)//': cannot open it to write its data: ', int(-fd, c_int))
      fd = -1
    end if
  end subroutine data_open

  !> Write n bytes from buf at byte offset `offset` of the file fd (thread-safe: pwrite(2),
  !! and no function with a deferred-length result); err (ERR_IO) on failure, its message
  !! the system's reason alone (the caller names what it was writing).
  subroutine data_write(fd, buf, n, offset, err)
    integer, intent(in) :: fd                             !< from data_open
    type(c_ptr), intent(in) :: buf                        !< the bytes
    integer(c_long_long), intent(in) :: n, offset         !< their number, where they go
    type(error_t), intent(out) :: err                     !< ERR_IO: the system's reason
    integer(c_int) :: e
    if (n <= 0) return
    e = rc_write_at(int(fd, c_int), buf, n, offset)
    if (e /= 0) call set_system_error(err, '', e)
  end subroutine data_write

  !> Close a file of data_open (nothing for fd < 0); err (ERR_IO) on failure (a full disk
  !! may show only here), its message the system's reason alone (the caller names the file).
  subroutine data_close(fd, err)
    integer, intent(inout) :: fd                          !< the descriptor; -1 on return
    type(error_t), intent(out) :: err                     !< ERR_IO: the system's reason
    integer(c_int) :: e
    if (fd < 0) return
    e = rc_close_data(int(fd, c_int))
    fd = -1
    if (e /= 0) call set_system_error(err, '', e)
  end subroutine data_close

  !> err = ERR_IO with `prefix` and the system's text of the errno value e. Builds the text
  !! in a local of explicit length (no deferred-length function result): data_write runs
  !! on several threads at once.
  subroutine set_system_error(err, prefix, e)
    type(error_t), intent(inout) :: err
    character(len=*), intent(in) :: prefix
    integer(c_int), intent(in) :: e
    character(kind=c_char) :: buf(160)
    character(len=len(prefix) + size(buf)) :: text
    integer :: n, i
    n = rc_error_text(e, buf, int(size(buf), c_int))
    n = min(max(n, 0), size(buf))
    text(1:len(prefix)) = prefix
    do i = 1, n
      text(len(prefix) + i:len(prefix) + i) = buf(i)
    end do
    call err%set(ERR_IO, text(1:len(prefix) + n))
  end subroutine set_system_error

end module files
