!> File-system helpers of the output stage: temporary names, atomic rename, parent
!! folders, removal and whole-file text output. Result and checkpoint files are written
!! under `temp_name(file)` and renamed to `file` only when complete.
module files
  use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
  implicit none (type, external)
  private

  public :: temp_name, replace_suffix, base_name, ensure_parent_dir, atomic_rename, remove_file, &
            write_text

  interface
    integer(c_int) function c_rename(old, new) bind(c, name='rename')
      import :: c_int, c_char
      implicit none (type, external)
      character(kind=c_char), intent(in) :: old(*), new(*)
    end function c_rename
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
  end interface

contains

  !> The temporary name under which `file` is written before it is renamed: `<file>.tmp`,
  !! in the same folder so that the rename is atomic.
  function temp_name(file) result(t)
    character(len=*), intent(in) :: file   !< final path
    character(len=:), allocatable :: t
    t = trim(file)//'.tmp'
  end function temp_name

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

  !> Create the folders leading to `file` (like mkdir -p of its parent); existing ones are
  !! left alone, failures show when the file itself is created.
  subroutine ensure_parent_dir(file)
    character(len=*), intent(in) :: file  !< a file path
    integer :: i, rc
    do i = 2, len_trim(file)
      if (file(i:i) == '/') rc = c_mkdir(file(1:i - 1)//c_null_char, int(o'755', c_int))
    end do
  end subroutine ensure_parent_dir

  !> rename(2): atomic within one file system; replaces `new`. ok = .false. on failure.
  subroutine atomic_rename(old, new, ok)
    character(len=*), intent(in) :: old   !< temporary name
    character(len=*), intent(in) :: new   !< final name
    logical, intent(out) :: ok            !< success
    ok = c_rename(trim(old)//c_null_char, trim(new)//c_null_char) == 0
  end subroutine atomic_rename

  !> unlink(2) `path` if it exists (a symbolic link is removed, not its target).
  subroutine remove_file(path)
    character(len=*), intent(in) :: path  !< file to remove
    integer :: rc
    rc = c_unlink(trim(path)//c_null_char)
  end subroutine remove_file

  !> Write `text` as the whole content of `path` (replaced). ok = .false. when the file
  !! cannot be created, written or closed (a full disk shows at the latest on close).
  subroutine write_text(path, text, ok)
    character(len=*), intent(in) :: path   !< file to write
    character(len=*), intent(in) :: text   !< its content, lines ended by new-line characters
    logical, intent(out) :: ok             !< success
    integer :: u, ios
    open (newunit=u, file=path, status='replace', access='stream', form='unformatted', &
          action='write', iostat=ios)
    ok = ios == 0
    if (.not. ok) return
    write (u, iostat=ios) text
    ok = ios == 0
    close (u, iostat=ios)
    ok = ok .and. ios == 0
  end subroutine write_text

end module files
