!> The compressed-sparse-column pattern of one body's stiffness on its free DOFs: from
!! the grid stencil on a structured mesh, from the cells' node adjacency on any other.
module stiffness_pattern
  use kinds, only: wp, i8
  use sorting, only: sort_ints
  use config, only: ELEM_Q1
  use mesh, only: mesh_t, node_id, cell_vertices
  use body_system, only: body_system_t
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  public :: build_pattern

contains

  !> The nodes that share a cell with grid node k (k itself included), in increasing
  !! node id order: Q1 the 3x3 block around it, P1 (diagonal lower-left to upper-right)
  !! the same without (i+1,j-1) and (i-1,j+1).
  pure subroutine node_stencil(mesh, k, nbr, nnbr)
    type(mesh_t), intent(in) :: mesh
    integer, intent(in) :: k
    integer, intent(out) :: nbr(9)
    integer, intent(out) :: nnbr
    integer :: di(9), dj(9), nstencil, i, j, ii, jj, s

    if (mesh%element == ELEM_Q1) then
      nstencil = 9
      di(1:9) = [-1, 0, 1, -1, 0, 1, -1, 0, 1]
      dj(1:9) = [-1, -1, -1, 0, 0, 0, 1, 1, 1]
    else
      nstencil = 7
      di(1:7) = [-1, 0, -1, 0, 1, 0, 1]
      dj(1:7) = [-1, -1, 0, 0, 0, 1, 1]
    end if
    i = mod(k - 1, mesh%nx + 1)
    j = (k - 1)/(mesh%nx + 1)
    nnbr = 0
    do s = 1, nstencil
      ii = i + di(s)
      jj = j + dj(s)
      if (ii < 0 .or. ii > mesh%nx .or. jj < 0 .or. jj > mesh%ny) cycle
      nnbr = nnbr + 1
      nbr(nnbr) = node_id(mesh, ii, jj)
    end do
  end subroutine node_stencil

  !> The CSC pattern of the stiffness on free DOFs (sys%colptr, sys%rowind; sys%val = 0),
  !! rows sorted in every column, from the node stencil of the grid. err = ERR_INPUT when
  !! the number of entries does not fit 32-bit indices.
  subroutine build_pattern(mesh, sys, err)
    type(mesh_t), intent(in) :: mesh           !< the body's mesh
    type(body_system_t), intent(inout) :: sys  !< with its DOF numbering; gets colptr, rowind, val = 0
    type(error_t), intent(out) :: err          !< ERR_INPUT when the pattern is too large
    integer :: p, s, cc, q, pos, nnbr
    integer(i8) :: nnz
    integer, allocatable :: aptr(:), adj(:), nbr(:)
    character(len=512) :: emsg

    if (mesh%structured) then
      allocate (nbr(9))
    else
      call node_adjacency(mesh, aptr, adj)
      allocate (nbr(maxval(aptr(2:) - aptr(:size(aptr) - 1))))
    end if
    allocate (sys%colptr(sys%n + 1))
    nnz = 0
    sys%colptr(1) = 0
    do p = 1, sys%n
      call neighbours(p)
      do s = 1, nnbr
        do cc = 1, 2
          if (sys%free_of(2*(nbr(s) - 1) + cc) > 0) nnz = nnz + 1
        end do
      end do
      if (nnz > int(huge(1), i8)) then
        write (emsg, '(a,i0,a)') 'body ', sys%id, ': the stiffness has more than 2^31-1 entries; '// &
          'the mesh is too large for 32-bit CSC indices'
        call err%set(ERR_INPUT, emsg)
        return
      end if
      sys%colptr(p + 1) = int(nnz)
    end do
    allocate (sys%rowind(nnz), sys%val(nnz))
    do p = 1, sys%n
      call neighbours(p)
      pos = sys%colptr(p)
      do s = 1, nnbr
        do cc = 1, 2
          q = sys%free_of(2*(nbr(s) - 1) + cc)
          if (q > 0) then
            pos = pos + 1
            sys%rowind(pos) = q - 1
          end if
        end do
      end do
    end do
    sys%val = 0.0_wp

  contains

    !> The nodes sharing a cell with free DOF p's node, in increasing node id: the grid
    !! stencil of a structured mesh, the adjacency list of any other.
    subroutine neighbours(p)
      integer, intent(in) :: p
      integer :: k
      k = (sys%dof_of(p) - 1)/2 + 1
      if (mesh%structured) then
        call node_stencil(mesh, k, nbr, nnbr)
      else
        nnbr = aptr(k + 1) - aptr(k)
        nbr(1:nnbr) = adj(aptr(k):aptr(k + 1) - 1)
      end if
    end subroutine neighbours
  end subroutine build_pattern

  !> The nodes that share a cell with each node (itself included), in increasing node id:
  !! node k's neighbours are adj(aptr(k):aptr(k+1)-1). Built from the cells by one sort of
  !! the (node, neighbour) pairs, for any mesh.
  subroutine node_adjacency(mesh, aptr, adj)
    type(mesh_t), intent(in) :: mesh
    integer, allocatable, intent(out) :: aptr(:), adj(:)
    integer, allocatable :: cnt(:), pairs(:), pos(:)
    integer :: c, a, b, nv, k, np, i, last
    ! pairs (k, l) of every cell, bucketed by k, then sorted and deduplicated per node
    allocate (cnt(mesh%nnode + 1))
    cnt = 0
    do c = 1, mesh%ncell
      nv = cell_vertices(mesh, c)
      do a = 1, nv
        k = mesh%cells(a, c)
        cnt(k + 1) = cnt(k + 1) + nv
      end do
    end do
    cnt(1) = 1
    do k = 1, mesh%nnode
      cnt(k + 1) = cnt(k + 1) + cnt(k)
    end do
    np = cnt(mesh%nnode + 1) - 1
    allocate (pairs(np), pos(mesh%nnode))
    pos = cnt(1:mesh%nnode)
    do c = 1, mesh%ncell
      nv = cell_vertices(mesh, c)
      do a = 1, nv
        k = mesh%cells(a, c)
        do b = 1, nv
          pairs(pos(k)) = mesh%cells(b, c)
          pos(k) = pos(k) + 1
        end do
      end do
    end do
    allocate (aptr(mesh%nnode + 1), adj(np))
    aptr(1) = 1
    i = 0
    do k = 1, mesh%nnode
      call sort_ints(pairs(cnt(k):cnt(k + 1) - 1))
      last = 0
      do a = cnt(k), cnt(k + 1) - 1
        if (pairs(a) == last) cycle
        last = pairs(a)
        i = i + 1
        adj(i) = last
      end do
      aptr(k + 1) = i + 1
    end do
  end subroutine node_adjacency

end module stiffness_pattern
