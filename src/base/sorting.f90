!> Sorting of small index lists: an element's DOFs, a level of the Cuthill-McKee ordering, a
!! node's neighbours.
module sorting
  implicit none (type, external)
  private

  public :: sort_by_key, sort_ints

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

  !> Insertion sort of a short list of integers, ascending, in place (a node's neighbour
  !! list: a few dozen entries).
  pure subroutine sort_ints(v)
    integer, intent(inout) :: v(:)      !< the list, sorted on return
    integer :: i, j, x
    do i = 2, size(v)
      x = v(i)
      j = i - 1
      do while (j >= 1)
        if (v(j) <= x) exit
        v(j + 1) = v(j)
        j = j - 1
      end do
      v(j + 1) = x
    end do
  end subroutine sort_ints

end module sorting
