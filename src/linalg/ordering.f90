!> Fill-reducing orderings computed from the geometry of the structured mesh (module
!! mesh), without a graph partitioner: geometric nested dissection of the node grid.
!!
!! Both element types (Q1, and P1 with its cells split along one diagonal) couple only
!! the nodes of a common grid cell, so one whole grid line of nodes separates the grid
!! into the nodes on either side of it. Nested dissection orders a box of nodes as: the
!! box on one side of its middle line, the box on the other side, then the line; boxes
!! below a small size are ordered naturally. On an N x N grid this gives O(N^2 log N)
!! nonzeros in the Cholesky factor, like METIS on these meshes, but it is deterministic,
!! linear in the number of nodes, and needs no global state (thread safe).
module ordering
  use kinds, only: i8
  use mesh, only: mesh_t
  use assembly, only: body_system_t
  implicit none (type, external)
  private

  public :: nested_dissection

  !> Boxes with fewer nodes than this are ordered naturally (no further dissection).
  !! On 512 x 256 Q1 cells, nnz(L) is 2.39e7 with 16, 2.68e7 with 64, 2.36e7 with 4
  !! (METIS: 2.50e7); the flop counts differ by under 3%.
  integer, parameter, public :: ND_LEAF_NODES = 16

  integer, parameter, public :: ND_OK = 0            !< info: success
  integer, parameter, public :: ND_BAD_SYSTEM = 1    !< info: mesh and system do not match
  integer, parameter, public :: ND_BAD_LAST = 2      !< info: an entry of `last` is out of range or repeated

contains

  !> Nested-dissection permutation of the free DOFs of one body that are not in `last`.
  !! perm(k) is the free DOF (1-based, 1..sys%n) placed k-th; size sys%n - size(last).
  !! Both DOFs of a node are consecutive; prescribed DOFs and DOFs in `last` are
  !! skipped. The caller appends `last` to obtain a full ordering with the interface
  !! last. Cost O(number of nodes).
  !! info: ND_OK, or ND_BAD_SYSTEM / ND_BAD_LAST with a sentence in msg (perm empty).
  subroutine nested_dissection(mesh, sys, last, perm, info, msg)
    type(mesh_t), intent(in) :: mesh                  !< the body's structured mesh
    type(body_system_t), intent(in) :: sys            !< its assembled system (free_of, n)
    integer, intent(in) :: last(:)                    !< 1-based free DOFs to leave out (ordered last by the caller)
    integer, allocatable, intent(out) :: perm(:)      !< the interior ordering, 1-based free DOFs
    integer, intent(out) :: info                      !< ND_OK or an error code
    character(len=*), intent(out), optional :: msg    !< one sentence on failure, else blank
    logical, allocatable :: skip(:)
    integer :: k, pos, nx1
    logical :: bad_map
    character(len=200) :: emsg

    info = ND_OK
    emsg = ''
    if (present(msg)) msg = ''
    if (mesh%nx < 1 .or. mesh%ny < 1 .or. sys%ndof /= 2*(mesh%nx + 1)*(mesh%ny + 1) &
        .or. .not. allocated(sys%free_of)) then
      write (emsg, '(a,i0,a,i0,a,i0,a)') 'nested dissection: the system (', sys%ndof, &
        ' DOFs) does not belong to a ', mesh%nx, ' x ', mesh%ny, ' cell mesh.'
      call fail(ND_BAD_SYSTEM)
      return
    else if (size(sys%free_of) /= sys%ndof) then
      emsg = 'nested dissection: the free-DOF map has the wrong size.'
      call fail(ND_BAD_SYSTEM)
      return
    end if

    allocate (skip(max(sys%n, 0)))
    skip = .false.
    do k = 1, size(last)
      if (last(k) < 1 .or. last(k) > sys%n) then
        write (emsg, '(a,i0,a,i0,a)') 'nested dissection: interface DOF ', last(k), ' (entry ', k, ') is out of range.'
        call fail(ND_BAD_LAST)
        return
      else if (skip(last(k))) then
        write (emsg, '(a,i0,a,i0,a)') 'nested dissection: interface DOF ', last(k), ' (entry ', k, ') is repeated.'
        call fail(ND_BAD_LAST)
        return
      end if
      skip(last(k)) = .true.
    end do

    allocate (perm(sys%n - size(last)))
    nx1 = mesh%nx + 1
    pos = 0
    bad_map = .false.
    call dissect(0, mesh%nx, 0, mesh%ny)
    if (bad_map .or. pos /= size(perm)) then
      ! free_of is not a bijection onto 1..n: the system is inconsistent
      write (emsg, '(a,i0,a,i0,a)') 'nested dissection: ordered ', pos, ' DOFs but expected ', size(perm), &
        ' (inconsistent free-DOF map).'
      call fail(ND_BAD_SYSTEM)
    end if

  contains

    !> Record a failure: the code, the sentence in emsg, an empty perm.
    subroutine fail(code)
      integer, intent(in) :: code
      info = code
      if (allocated(perm)) deallocate (perm)
      allocate (perm(0))
      if (present(msg)) msg = emsg
    end subroutine fail

    !> Order the box of grid nodes [i0,i1] x [j0,j1] (empty if i1 < i0 or j1 < j0).
    recursive subroutine dissect(i0, i1, j0, j1)
      integer, intent(in) :: i0, i1, j0, j1
      integer :: ni, nj, mid
      ni = i1 - i0 + 1
      nj = j1 - j0 + 1
      if (ni <= 0 .or. nj <= 0) return
      if (int(ni, i8)*int(nj, i8) < int(ND_LEAF_NODES, i8)) then
        call emit(i0, i1, j0, j1)
      else if (ni >= nj) then
        mid = i0 + (ni - 1)/2          ! separator: the grid line i = mid
        call dissect(i0, mid - 1, j0, j1)
        call dissect(mid + 1, i1, j0, j1)
        call emit(mid, mid, j0, j1)
      else
        mid = j0 + (nj - 1)/2          ! separator: the grid line j = mid
        call dissect(i0, i1, j0, mid - 1)
        call dissect(i0, i1, mid + 1, j1)
        call emit(i0, i1, mid, mid)
      end if
    end subroutine dissect

    !> Append the free, non-skipped DOFs of the box's nodes in natural order, the
    !! shorter side of the box varying fastest (smaller profile).
    subroutine emit(i0, i1, j0, j1)
      integer, intent(in) :: i0, i1, j0, j1
      integer :: i, j
      if (i1 - i0 <= j1 - j0) then
        do j = j0, j1
          do i = i0, i1
            call emit_node(1 + i + j*nx1)
          end do
        end do
      else
        do i = i0, i1
          do j = j0, j1
            call emit_node(1 + i + j*nx1)
          end do
        end do
      end if
    end subroutine emit

    !> Append the free, non-skipped DOFs of one node (x then y).
    subroutine emit_node(node)
      integer, intent(in) :: node
      integer :: c, f
      do c = 1, 2
        f = sys%free_of(2*(node - 1) + c)
        if (f <= 0) cycle
        if (f > sys%n) then
          bad_map = .true.
          cycle
        end if
        if (skip(f)) cycle
        pos = pos + 1
        if (pos <= size(perm)) perm(pos) = f
      end do
    end subroutine emit_node

  end subroutine nested_dissection

end module ordering
