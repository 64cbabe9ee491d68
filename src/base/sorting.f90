!> Sorting of index lists: insertion sorts for the short ones (an element's DOFs, a level of
!! the Cuthill-McKee ordering, a node's neighbours), a merge sort for a mesh's long ones.
module sorting
  implicit none (type, external)
  private

  public :: sort_by_key, sort_ints, merge_sort_by_keys, largest_first

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

  !> Stable bottom-up merge sort of the indices `idx` by the columns `keys(:, idx(i))`,
  !! compared lexicographically (first row first): n log n comparisons, for the long lists
  !! (a mesh's node tags, its cells' node sets, a deck's group names as character codes).
  !! The comparison is written out here, not passed in: a procedure argument that is an
  !! internal procedure needs a trampoline, which makes the program's stack executable.
  subroutine merge_sort_by_keys(idx, keys)
    integer, intent(inout) :: idx(:)        !< indices into the columns of keys, sorted on return
    integer, intent(in) :: keys(:, :)       !< (k, *) the keys
    integer, allocatable :: work(:)
    integer :: n, width, lo, mid, hi, i, j, k
    n = size(idx)
    if (n < 2) return
    allocate (work(n))
    width = 1
    do while (width < n)
      do lo = 1, n, 2*width
        mid = min(lo + width, n + 1)
        hi = min(lo + 2*width, n + 1)
        i = lo
        j = mid
        do k = lo, hi - 1
          if (i < mid .and. (j >= hi .or. .not. column_less(idx(min(j, n)), idx(min(i, n))))) then
            work(k) = idx(i)
            i = i + 1
          else
            work(k) = idx(j)
            j = j + 1
          end if
        end do
      end do
      idx = work
      width = 2*width
    end do
  contains
    logical function column_less(a, b)
      integer, intent(in) :: a, b
      integer :: m
      column_less = .false.
      do m = 1, size(keys, 1)
        if (keys(m, a) /= keys(m, b)) then
          column_less = keys(m, a) < keys(m, b)
          return
        end if
      end do
    end function column_less
  end subroutine merge_sort_by_keys

  !> The indices 1..size(sizes) by decreasing size, ties by index (the threads' order of
  !! the bodies: the largest first).
  function largest_first(sizes) result(order)
    integer, intent(in) :: sizes(:)
    integer, allocatable :: order(:)
    integer :: i
    order = [(i, i=1, size(sizes))]
    call merge_sort_by_keys(order, reshape(-sizes, [1, size(sizes)]))
  end function largest_first

end module sorting
