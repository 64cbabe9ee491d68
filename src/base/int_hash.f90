!> An open-addressing hash set of non-negative 64-bit integer keys (linear probing, at most
!! half full). The table gives each key a slot; data attached to a key are kept by the
!! caller in its own arrays indexed by the slot (0..mask).
module int_hash
  use kinds, only: i8
  use errors, only: error_t, ERR_MEMORY
  use strings, only: i2s
  implicit none (type, external)
  private

  public :: hash_init, hash_slot

  integer(i8), parameter, public :: HASH_EMPTY = -1_i8   !< the key of an unused slot

  !> The table: key(slot) = HASH_EMPTY or the key stored there.
  type, public :: int_hash_t
    integer(i8), allocatable :: key(:)   !< (0:mask) the keys
    integer(i8) :: mask = 0              !< capacity - 1 (the capacity is a power of two)
  end type int_hash_t

contains

  !> An empty table with room for n keys (capacity at least 2n, at least 16). err
  !! (ERR_MEMORY) when the table cannot be allocated (the caller names what it was for).
  subroutine hash_init(h, n, err)
    type(int_hash_t), intent(out) :: h   !< the table
    integer, intent(in) :: n             !< keys to hold
    type(error_t), intent(out) :: err    !< ERR_MEMORY: no room for the table
    integer(i8) :: capacity
    integer :: st
    capacity = 16
    do while (capacity < 2_i8*n)
      capacity = 2*capacity
    end do
    allocate (h%key(0:capacity - 1), stat=st)
    if (st /= 0) then
      call err%set(ERR_MEMORY, 'not enough memory for a hash table of '//i2s(n)//' keys')
      return
    end if
    h%key = HASH_EMPTY
    h%mask = capacity - 1
  end subroutine hash_init

  !> The slot (0-based) holding `key`, or the empty slot where it goes. The key's two
  !! 32-bit halves are folded and scrambled by a 32-bit multiplicative mix whose products
  !! stay below 2**63 (no integer overflow).
  pure integer function hash_slot(h, key) result(slot)
    type(int_hash_t), intent(in) :: h    !< the table (not full)
    integer(i8), intent(in) :: key       !< a non-negative key
    integer(i8), parameter :: low32 = 2_i8**32 - 1, mult = 73244475_i8
    integer(i8) :: k
    k = ieor(iand(key, low32), ishft(key, -32))
    k = iand(ieor(k, ishft(k, -16))*mult, low32)
    k = iand(ieor(k, ishft(k, -16))*mult, low32)
    k = ieor(k, ishft(k, -16))
    k = iand(k, h%mask)
    do while (h%key(k) /= HASH_EMPTY .and. h%key(k) /= key)
      k = iand(k + 1, h%mask)
    end do
    slot = int(k)
  end function hash_slot

end module int_hash
