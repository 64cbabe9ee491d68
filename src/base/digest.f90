!> Content hashes of files: FNV-1a 64 over the bytes, as 16 hexadecimal digits. A
!! checkpoint records the hash of every mesh file its run read, so that a mesh replaced
!! at the same path is recognized on restart. Not a cryptographic hash: it tells an
!! edited or replaced file from the original, it does not resist a forger.
module digest
  use, intrinsic :: iso_fortran_env, only: int8, int64
  use errors, only: error_t, ERR_IO
  implicit none (type, external)
  private

  public :: file_digest, text_digest

  integer(int64), parameter :: MASK32 = 4294967295_int64      ! 2**32 - 1
  integer(int64), parameter :: MASK24 = 16777215_int64        ! 2**24 - 1
  integer(int64), parameter :: PRIME_LOW = 435_int64          ! 0x1b3: the FNV prime is 2**40 + 0x1b3
  ! the FNV-1a 64 offset basis 0xcbf29ce484222325 in two 32-bit halves
  integer(int64), parameter :: BASIS_HI = 3421674724_int64, BASIS_LO = 2216829733_int64
  integer, parameter :: CHUNK = 1048576                       ! bytes read at a time

contains

  !> The FNV-1a 64 hash of the bytes of file `path` (16 lowercase hex digits). err
  !! (ERR_IO) when the file cannot be opened or read whole, or is not a regular file.
  subroutine file_digest(path, hex, err)
    character(len=*), intent(in) :: path             !< the file
    character(len=16), intent(out) :: hex            !< its hash
    type(error_t), intent(out) :: err                !< why it could not be hashed
    integer(int8), allocatable :: buf(:)
    integer(int64) :: hi, lo, size_, left
    integer :: u, ios, n
    character(len=256) :: iom
    hex = ''
    hi = BASIS_HI
    lo = BASIS_LO
    open (newunit=u, file=path, access='stream', form='unformatted', action='read', status='old', &
          iostat=ios, iomsg=iom)
    if (ios /= 0) then
      call err%set(ERR_IO, 'file '//path//' cannot be opened for its content hash ('//trim(iom)//')')
      return
    end if
    inquire (unit=u, size=size_)
    if (size_ < 0) then
      close (u)
      call err%set(ERR_IO, 'file '//path//' has no size (not a regular file); its content cannot be hashed')
      return
    end if
    allocate (buf(int(min(size_, int(CHUNK, int64)))))
    left = size_
    do while (left > 0)
      n = int(min(left, int(CHUNK, int64)))
      read (u, iostat=ios, iomsg=iom) buf(1:n)
      if (ios /= 0) then
        close (u)
        call err%set(ERR_IO, 'file '//path//' cannot be read whole for its content hash ('//trim(iom)//')')
        return
      end if
      call mix(buf(1:n), hi, lo)
      left = left - n
    end do
    close (u)
    hex = to_hex(hi, lo)
  end subroutine file_digest

  !> The FNV-1a 64 hash of the characters of `text` (16 lowercase hex digits): of the bytes
  !! of a file read whole into `text`, the same as file_digest's (no copy of the text: a mesh
  !! file of tens of MB is hashed where it lies).
  function text_digest(text) result(hex)
    character(len=*), intent(in) :: text   !< the bytes to hash
    character(len=16) :: hex
    integer(int64) :: hi, lo, i
    hi = BASIS_HI
    lo = BASIS_LO
    do i = 1, len(text, kind=int64)
      call step(int(iachar(text(i:i)), int64), hi, lo)
    end do
    hex = to_hex(hi, lo)
  end function text_digest

  !> FNV-1a 64 over `bytes`.
  pure subroutine mix(bytes, hi, lo)
    integer(int8), intent(in) :: bytes(:)
    integer(int64), intent(inout) :: hi, lo
    integer :: i
    do i = 1, size(bytes)
      call step(int(bytes(i), int64), hi, lo)
    end do
  end subroutine mix

  !> One byte (its low 8 bits) into the FNV-1a 64 state, held as two 32-bit halves (hi, lo)
  !! so that no integer operation overflows: h = (h xor byte) * (2**40 + 0x1b3) mod 2**64.
  pure subroutine step(byte, hi, lo)
    integer(int64), intent(in) :: byte
    integer(int64), intent(inout) :: hi, lo
    integer(int64) :: t
    lo = ieor(lo, iand(byte, 255_int64))
    ! h * 0x1b3 plus h * 2**40; of the latter only lo's low 24 bits stay below 2**64
    t = lo*PRIME_LOW
    hi = iand(hi*PRIME_LOW + shiftr(t, 32) + shiftl(iand(lo, MASK24), 8), MASK32)
    lo = iand(t, MASK32)
  end subroutine step

  !> The hash as 16 lowercase hex digits.
  function to_hex(hi, lo) result(hex)
    integer(int64), intent(in) :: hi, lo
    character(len=16) :: hex
    write (hex, '(z8.8,z8.8)') hi, lo
    hex = lower(hex)
  end function to_hex

  pure function lower(s) result(t)
    character(len=*), intent(in) :: s
    character(len=len(s)) :: t
    integer :: i
    t = s
    do i = 1, len(s)
      if (t(i:i) >= 'A' .and. t(i:i) <= 'F') t(i:i) = achar(iachar(t(i:i)) + 32)
    end do
  end function lower

end module digest
