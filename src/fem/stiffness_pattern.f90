!> The compressed-sparse-column pattern of one body's stiffness on its free DOFs: from
!! the grid stencil on a structured mesh, from the cells' node adjacency on any other.
module stiffness_pattern
  use kinds, only: wp, i8
  use space, only: NCOMP, node_dof
  use, intrinsic :: iso_fortran_env, only: int16
  use config, only: ELEM_Q1
  use mesh, only: mesh_t, node_id, cell_vertices
  use body_system, only: body_system_t
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  public :: build_pattern

  !> The code of "vertex a of cell c" in a node's list of cells: NSLOT (c - 1) + a - 1
  integer, parameter :: NSLOT = 8

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
  !! rows sorted in every column: the free DOFs of the nodes sharing a cell with the
  !! column's node (the grid stencil, or the cells' node adjacency), formed once per node
  !! for both of its columns. On a mesh that is not structured, also where each cell's
  !! entries go (cell_row), so that its assembly needs no search. err = ERR_INPUT when the
  !! number of entries does not fit 32-bit indices.
  subroutine build_pattern(mesh, sys, err, cell_row)
    type(mesh_t), intent(in) :: mesh           !< the body's mesh
    type(body_system_t), intent(inout) :: sys  !< with its DOF numbering; gets colptr, rowind, val = 0
    type(error_t), intent(out) :: err          !< ERR_INPUT when the pattern is too large
    !> (nv, nv, ncell), nv the most vertices of a cell; a mesh that is not structured only
    !! (else, or when a column has more than huge(0_int16) rows, not allocated):
    !! cell_row(a, b, c) = how many rows precede the first of vertex a's rows in each
    !! column of vertex b of cell c (the column's free rows, in order); defined where
    !! vertex b has a free DOF
    integer(int16), allocatable, intent(out), optional :: cell_row(:, :, :)
    integer :: p, s, cc, k, q, nnbr, nrow, first, t, c, a, b, nv, maxrow
    integer(i8) :: nnz
    integer, allocatable :: aptr(:), adj(:), nbr(:), rows(:), cptr(:), ccell(:), nv_of(:), rowoff(:)
    logical :: with_map
    character(len=512) :: emsg

    if (mesh%structured) then
      allocate (nbr(9))
    else
      call node_adjacency(mesh, aptr, adj, cptr, ccell, nv_of)
      allocate (nbr(maxval(aptr(2:) - aptr(:size(aptr) - 1))))
    end if
    allocate (rows(NCOMP*size(nbr)))
    ! column counts: colptr(p + 1) = the entries of free DOF p, then their running sum
    allocate (sys%colptr(sys%n + 1))
    sys%colptr = 0
    maxrow = 0
    do k = 1, mesh%nnode
      if (all(sys%free_of(node_dof(k, 1):node_dof(k, NCOMP)) == 0)) cycle
      call neighbours(k)
      nrow = 0
      do s = 1, nnbr
        do cc = 1, NCOMP
          if (sys%free_of(node_dof(nbr(s), cc)) > 0) nrow = nrow + 1
        end do
      end do
      maxrow = max(maxrow, nrow)
      do cc = 1, NCOMP
        p = sys%free_of(node_dof(k, cc))
        if (p > 0) sys%colptr(p + 1) = nrow
      end do
    end do
    ! the places of each cell's entries, unless an offset would not fit 16 bits
    with_map = present(cell_row) .and. .not. mesh%structured .and. maxrow <= huge(0_int16) .and. NCOMP == 2
    if (with_map) then
      nv = max(3, maxval(nv_of))
      allocate (cell_row(nv, nv, mesh%ncell), rowoff(mesh%nnode))
    end if
    nnz = 0
    do p = 1, sys%n
      nnz = nnz + sys%colptr(p + 1)
      if (nnz > int(huge(1), i8)) then
        write (emsg, '(a,i0,a)') 'body ', sys%id, ': the stiffness has more than 2^31-1 entries; '// &
          'the mesh is too large for 32-bit CSC indices'
        call err%set(ERR_INPUT, emsg)
        return
      end if
      sys%colptr(p + 1) = int(nnz)
    end do
    allocate (sys%rowind(nnz), sys%val(nnz))
    do k = 1, mesh%nnode
      if (all(sys%free_of(node_dof(k, 1):node_dof(k, NCOMP)) == 0)) cycle
      call neighbours(k)
      nrow = 0
      do s = 1, nnbr
        if (with_map) rowoff(nbr(s)) = nrow
        do cc = 1, NCOMP
          q = sys%free_of(node_dof(nbr(s), cc))
          if (q > 0) then
            nrow = nrow + 1
            rows(nrow) = q - 1
          end if
        end do
      end do
      do cc = 1, NCOMP
        p = sys%free_of(node_dof(k, cc))
        if (p == 0) cycle
        first = sys%colptr(p)
        sys%rowind(first + 1:first + nrow) = rows(1:nrow)
      end do
      if (.not. with_map) cycle
      ! each cell of node k: the rows of its vertices in node k's columns
      do t = cptr(k), cptr(k + 1) - 1
        c = ccell(t)/NSLOT + 1
        b = ccell(t) - NSLOT*(c - 1) + 1
        do a = 1, nv_of(c)
          cell_row(a, b, c) = int(rowoff(mesh%cells(a, c)), int16)
        end do
      end do
    end do
    sys%val = 0.0_wp

  contains

    !> The nodes sharing a cell with node k, in increasing node id: the grid stencil of
    !! a structured mesh, the adjacency list of any other.
    subroutine neighbours(k)
      integer, intent(in) :: k
      if (mesh%structured) then
        call node_stencil(mesh, k, nbr, nnbr)
      else
        nnbr = aptr(k + 1) - aptr(k)
        nbr(1:nnbr) = adj(aptr(k):aptr(k + 1) - 1)
      end if
    end subroutine neighbours
  end subroutine build_pattern

  !> The nodes that share a cell with each node (itself included), in increasing node id:
  !! node k's neighbours are adj(aptr(k):aptr(k+1)-1). From the cells of each node, a
  !! counting sort of the cells by vertex: node k is vertex a of cell c for each
  !! ccell(t) = NSLOT (c - 1) + a - 1, t = cptr(k) .. cptr(k+1)-1, c increasing; their
  !! vertices (nv(c) of cell c), each kept once by a mark,
  !! then sorted; for any mesh.
  subroutine node_adjacency(mesh, aptr, adj, cptr, ccell, nv)
    type(mesh_t), intent(in) :: mesh
    integer, allocatable, intent(out) :: aptr(:), adj(:), cptr(:), ccell(:), nv(:)
    integer, allocatable :: pos(:), mark(:)
    integer :: c, a, k, l, t, i, first
    allocate (nv(mesh%ncell), cptr(mesh%nnode + 1))
    cptr = 0
    do c = 1, mesh%ncell
      nv(c) = cell_vertices(mesh, c)
      do a = 1, nv(c)
        k = mesh%cells(a, c)
        cptr(k + 1) = cptr(k + 1) + 1
      end do
    end do
    cptr(1) = 1
    do k = 1, mesh%nnode
      cptr(k + 1) = cptr(k + 1) + cptr(k)
    end do
    allocate (ccell(cptr(mesh%nnode + 1) - 1), pos(mesh%nnode))
    pos = cptr(1:mesh%nnode)
    do c = 1, mesh%ncell
      do a = 1, nv(c)
        k = mesh%cells(a, c)
        ccell(pos(k)) = NSLOT*(c - 1) + a - 1
        pos(k) = pos(k) + 1
      end do
    end do
    ! at most the vertices of each node's cells
    allocate (aptr(mesh%nnode + 1), adj(sum(nv)*max(4, maxval(nv))), mark(mesh%nnode))
    mark = 0
    aptr(1) = 1
    i = 0
    do k = 1, mesh%nnode
      first = i + 1
      do t = cptr(k), cptr(k + 1) - 1
        c = ccell(t)/NSLOT + 1
        do a = 1, nv(c)          ! appended always, kept when not marked (no branch)
          l = mesh%cells(a, c)
          adj(i + 1) = l
          i = i + merge(1, 0, mark(l) /= k)
          mark(l) = k
        end do
      end do
      call sort_distinct(adj(first:i))
      aptr(k + 1) = i + 1
    end do
  end subroutine node_adjacency

  !> Sort a short list of distinct integers (a node's neighbours) ascending: each goes to
  !! the place given by the count of smaller ones, without a data-dependent branch.
  pure subroutine sort_distinct(v)
    integer, intent(inout) :: v(:)
    integer :: w(size(v)), a, b, r
    do a = 1, size(v)
      r = 1
      do b = 1, size(v)
        r = r + merge(1, 0, v(b) < v(a))
      end do
      w(r) = v(a)
    end do
    v = w
  end subroutine sort_distinct

end module stiffness_pattern
