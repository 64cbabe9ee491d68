!> Sorting of small index lists: an element's DOFs, a level of the Cuthill-McKee ordering.
module sorting
  implicit none (type, external)
  private

  public :: sort_by_key

contains

  !> Stable insertion sort of the indices `perm` by `key(perm(i))`, ascending. The lists
  !! sorted here are short (an element's DOFs, one level of new nodes), where insertion
  !! sort is fastest and keeps equal keys in their order.
  pure subroutine sort_by_key(perm, key)
    integer, intent(inout) :: perm(:)   !< indices into key, sorted on return
    integer, intent(in) :: key(:)       !< the keys
    integer :: i, j, t
    do i = 2, size(perm)
      t = perm(i)
      j = i - 1
      do while (j >= 1)
        if (key(perm(j)) <= key(t)) exit
        perm(j + 1) = perm(j)
        j = j - 1
      end do
      perm(j + 1) = t
    end do
  end subroutine sort_by_key

end module sorting
