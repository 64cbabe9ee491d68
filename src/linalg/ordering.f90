!> Fill-reducing orderings of a body's free DOFs: geometric nested dissection of a plane
!! body's mesh, without a graph partitioner, and METIS on the node graph of a solid body.
!! The mesh and the system come as plain arrays (the grid's size or the node coordinates,
!! the DOF maps, the stiffness pattern), so this module knows nothing of the FE stages.
!!
!! Structured meshes (grid_dissection): both element types (Q1, and P1 with its cells split
!! along one diagonal) couple only the nodes of a common grid cell, so one whole grid line
!! of nodes separates the grid into the nodes on either side of it. Nested dissection
!! orders a box of nodes as: the box on one side of its middle line, the box on the other
!! side, then the line; boxes below a small size are ordered naturally. On an N x N grid
!! this gives O(N^2 log N) nonzeros in the Cholesky factor, like METIS on these meshes, but
!! it is deterministic, linear in the number of nodes, and needs no global state (thread
!! safe).
!!
!! Any other mesh (coordinate_bisection): recursive coordinate bisection of the node graph
!! (two nodes adjacent when the stiffness couples them). A node set is cut across its
!! longer extent (and across the other one too when it is at least half as long) at the
!! median coordinate or at 40, 45, 55 or 60% of its nodes; a cut's separator is the
!! smaller of the two sets "nodes of one side with a neighbour on the other", and the cut
!! with the smallest separator is kept. The two sides without it are ordered first
!! (recursively), then the separator. Nodes are renumbered by x (memory locality) and
!! kept sorted by x and by y (one sort at the start, stable partitions after), and only
!! nodes within one edge extent of a cut are examined for the separator, so the whole
!! ordering costs O(n log n) plus the graph (O(nnz)) and is deterministic. On a 64 x 64 Q1
!! grid with randomly moved nodes nnz(L) is 0.98x METIS's, at 1024 x 512 1.05x.
!!
!! Solid bodies (node_dissection): METIS nested dissection (cholmod_iface%cm_metis_order) of
!! the graph of the nodes instead of the DOFs, NCOMP times fewer vertices and about NCOMP^2
!! times fewer edges, each node's DOFs then placed together. The nodes are found in the
!! stiffness pattern alone: a node's free DOFs are consecutive in the free numbering and
!! share one column pattern (the same neighbouring nodes), so a node is a run of at most
!! NCOMP consecutive free DOFs with identical columns. Two DOFs of different nodes are put
!! together only when their columns are identical too, and such DOFs are indistinguishable
!! to the elimination (the same fill whichever comes first).
!!
!! DOFs: node k, component c (1 = x, 2 = y) is global DOF 2*(k-1)+c; free_of maps a global
!! DOF to its free index (0: prescribed), dof_of a free index to its global DOF.
module ordering
  use kinds, only: wp, i8
  use space, only: NCOMP, node_dof
  use errors, only: error_t, ERR_NUMERICAL, ERR_MEMORY
  use cholmod_iface, only: cm_metis_order
  implicit none (type, external)
  private

  public :: grid_dissection, coordinate_bisection, node_dissection, node_groups

  !> Boxes with fewer nodes than this are ordered naturally (no further dissection); the
  !! factor's size depends little on it (within 12% from 4 to 64 on 512 x 256 Q1 cells).
  integer, parameter, public :: ND_LEAF_NODES = 16

  !> Unstructured meshes: node sets with fewer nodes than this are not bisected further.
  integer, parameter, public :: RCB_LEAF_NODES = 16

  !> The order being built: the free DOFs placed so far, and those left out.
  type :: order_t
    integer, allocatable :: perm(:)       ! the interior order
    integer :: pos = 0                    ! entries of perm filled
    logical, allocatable :: skip(:)       ! (n) the DOFs of `last`
    logical :: bad_map = .false.          ! free_of maps a DOF beyond n
  end type order_t

  !> The node graph of a general mesh, on local node numbers 1..na.
  type :: node_graph_t
    integer, allocatable :: mesh_node(:)      ! (na) the mesh node of each
    real(wp), allocatable :: xy_local(:, :)   ! (2, na) their coordinates
    integer, allocatable :: xadj(:), adj(:)   ! neighbours (CSR, 0-based pointers)
    integer, allocatable :: sorted(:, :)      ! (na, 2) nodes sorted by x, by y
    integer, allocatable :: label(:)          ! partition labels
    integer, allocatable :: work(:)           ! work array
    integer, allocatable :: position(:, :)    ! (na, 2) position of each node in sorted(:, axis)
    real(wp) :: edge_extent(2) = 0.0_wp       ! the largest edge extent in x and y
  end type node_graph_t

contains

  !> Nested-dissection permutation of the free DOFs of a body on a structured nx x ny cell
  !! grid (node (i,j) is node 1 + i + j*(nx+1)) that are not in `last`, along its grid lines
  !! (cost O(number of nodes)). perm(k) is the free DOF (1-based, 1..n) placed k-th; size
  !! n - size(last). Both DOFs of a node are consecutive; prescribed DOFs and DOFs in
  !! `last` are skipped. The caller appends `last` to obtain a full ordering with the
  !! interface last. On failure (the system does not belong to the mesh, `last` out of range
  !! or repeated) ERR_NUMERICAL with a sentence, perm empty.
  subroutine grid_dissection(nx, ny, free_of, n, last, perm, err)
    integer, intent(in) :: nx, ny                     !< grid cells along x and y
    integer, intent(in) :: free_of(:)                 !< (2*(nx+1)*(ny+1)) free index of each DOF, 0 if prescribed
    integer, intent(in) :: n                          !< the number of free DOFs
    integer, intent(in) :: last(:)                    !< 1-based free DOFs to leave out (ordered last by the caller)
    integer, allocatable, intent(out) :: perm(:)      !< the interior ordering, 1-based free DOFs
    type(error_t), intent(out) :: err                 !< ERR_NUMERICAL with one sentence (perm empty)
    type(order_t) :: order
    integer :: nx1
    character(len=200) :: emsg

    if (nx < 1 .or. ny < 1 .or. size(free_of) /= 2*(nx + 1)*(ny + 1)) then
      write (emsg, '(a,i0,a,i0,a,i0,a)') 'nested dissection: the system (', size(free_of), &
        ' DOFs) does not belong to a ', nx, ' x ', ny, ' cell mesh.'
      call err%set(ERR_NUMERICAL, emsg)
    else
      call start_order(n, last, order, err)
    end if
    if (.not. err%failed()) then
      nx1 = nx + 1
      call dissect(0, nx, 0, ny)
      call finish_order(order, err)
    end if
    call hand_over(order, err, perm)

  contains

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
            call emit_node(order, free_of, n, 1 + i + j*nx1)
          end do
        end do
      else
        do i = i0, i1
          do j = j0, j1
            call emit_node(order, free_of, n, 1 + i + j*nx1)
          end do
        end do
      end if
    end subroutine emit

  end subroutine grid_dissection

  !> Nested-dissection permutation of the free DOFs not in `last` of a body on any mesh, by
  !! recursive coordinate bisection of the node graph of the stiffness pattern (cost
  !! O(nnz log n)). perm as grid_dissection's.
  subroutine coordinate_bisection(xy, free_of, dof_of, colptr, rowind, last, perm, err)
    real(wp), intent(in) :: xy(:, :)                  !< (2, nnode) node coordinates [length]
    integer, intent(in) :: free_of(:)                 !< (2*nnode) free index of each DOF, 0 if prescribed
    integer, intent(in) :: dof_of(:)                  !< (n) global DOF of each free index
    integer, intent(in) :: colptr(:)                  !< (n+1) 0-based CSC column pointers of the stiffness
    integer, intent(in) :: rowind(:)                  !< 0-based row indices (free DOFs)
    integer, intent(in) :: last(:)                    !< 1-based free DOFs to leave out (ordered last by the caller)
    integer, allocatable, intent(out) :: perm(:)      !< the interior ordering, 1-based free DOFs
    type(error_t), intent(out) :: err                 !< ERR_NUMERICAL with one sentence (perm empty)
    type(order_t) :: order
    type(node_graph_t) :: graph
    integer :: n, stamp
    character(len=200) :: emsg

    emsg = ''
    n = size(dof_of)
    if (general_arrays_ok(xy, free_of, dof_of, colptr, rowind, emsg)) then
      call start_order(n, last, order, err)
    else
      call err%set(ERR_NUMERICAL, emsg)
    end if
    if (.not. err%failed()) then
      if (build_node_graph(xy, free_of, dof_of, colptr, rowind, n, order%skip, graph, emsg)) then
        stamp = 0
        call bisect(1, size(graph%sorted, 1))
        call finish_order(order, err)
      else
        call err%set(ERR_NUMERICAL, emsg)
      end if
    end if
    call hand_over(order, err, perm)

  contains

    !> Order the (local) nodes graph%sorted(lo:hi, :) (the same set in both columns) by recursive
    !! coordinate bisection: cut across x or y (both are tried when neither extent is
    !! below half the other) at the median or at 40, 45, 55 or 60% of the nodes, keeping
    !! the cut with the smallest separator (the smaller set of nodes of one side with a
    !! neighbour on the other); the two sides without it first, then the separator.
    recursive subroutine bisect(lo, hi)
      integer, intent(in) :: lo, hi
      integer, parameter :: fracs(5) = [50, 45, 55, 40, 60]   ! candidate cuts [% of the nodes]
      integer :: m, axis, ax, p, i, a, k, f, seg, lset, rset, sset, nl, nr, lbl, ns, nsl, nsr
      integer :: best, best_ax, best_p, best_side
      real(wp) :: ext(2)

      m = hi - lo + 1
      if (m <= 0) return
      ext(1) = graph%xy_local(1, graph%sorted(hi, 1)) - graph%xy_local(1, graph%sorted(lo, 1))
      ext(2) = graph%xy_local(2, graph%sorted(hi, 2)) - graph%xy_local(2, graph%sorted(lo, 2))
      axis = 1
      if (ext(2) > ext(1)) axis = 2
      if (m < RCB_LEAF_NODES .or. .not. ext(axis) > 0.0_wp) then
        ! a leaf: along the longer extent, the shorter one varying fastest
        do i = lo, hi
          call emit_node(order, free_of, n, graph%mesh_node(graph%sorted(i, axis)))
        end do
        return
      end if

      ! this set's nodes: label seg, and their positions in both sorted lists
      seg = stamp + 1
      lset = stamp + 2
      rset = stamp + 3
      sset = stamp + 4
      stamp = stamp + 4
      graph%label(graph%sorted(lo:hi, 1)) = seg
      do a = 1, 2
        do i = lo, hi
          graph%position(graph%sorted(i, a), a) = i
        end do
      end do
      best = huge(1)
      best_ax = axis
      best_p = 0
      best_side = 1
      do k = 0, 1
        ax = merge(axis, other_axis(axis), k == 0)
        if (k == 1 .and. .not. ext(ax) >= 0.5_wp*ext(axis)) exit
        do f = 1, size(fracs)
          p = cut_at(lo, hi, ax, lo + int((int(m, i8)*fracs(f))/100))
          if (p <= lo .or. p > hi) cycle
          nsl = touching(p - 1, lo, -1, ax, p, 0)
          nsr = touching(p, hi, 1, ax, p, 0)
          ns = min(nsl, nsr)
          if (ns < best) then
            best = ns
            best_ax = ax
            best_p = p
            best_side = merge(-1, 1, nsl < nsr)
          end if
        end do
      end do
      if (best_p == 0) then                  ! no cut possible (cannot happen: ext > 0)
        do i = lo, hi
          call emit_node(order, free_of, n, graph%mesh_node(graph%sorted(i, axis)))
        end do
        return
      end if
      axis = best_ax
      p = best_p
      graph%label(graph%sorted(lo:p - 1, axis)) = lset
      graph%label(graph%sorted(p:hi, axis)) = rset
      if (best_side < 0) then
        ns = touching(p - 1, lo, -1, axis, p, sset)
      else
        ns = touching(p, hi, 1, axis, p, sset)
      end if

      ! stable partition of both sorted lists: left side, right side, separator
      do a = 1, 2
        k = lo - 1
        do lbl = lset, sset
          do i = lo, hi
            if (graph%label(graph%sorted(i, a)) == lbl) then
              k = k + 1
              graph%work(k) = graph%sorted(i, a)
            end if
          end do
          if (a == 1 .and. lbl == lset) nl = k - lo + 1
          if (a == 1 .and. lbl == rset) nr = k - lo + 1 - nl
        end do
        graph%sorted(lo:hi, a) = graph%work(lo:hi)
      end do

      call bisect(lo, lo + nl - 1)
      call bisect(lo + nl, lo + nl + nr - 1)
      ! the separator, along its length (sorted by the other coordinate)
      do i = lo + nl + nr, hi
        call emit_node(order, free_of, n, graph%mesh_node(graph%sorted(i, other_axis(axis))))
      end do
    end subroutine bisect

    !> The first position of the right side of a cut of graph%sorted(lo:hi, axis) near position
    !! mid: right = coordinate >= v = that of graph%sorted(mid), or > v when v is the least.
    integer function cut_at(lo, hi, axis, mid) result(p)
      integer, intent(in) :: lo, hi, axis, mid
      real(wp) :: v
      v = graph%xy_local(axis, graph%sorted(mid, axis))
      p = mid
      do while (p > lo)
        if (graph%xy_local(axis, graph%sorted(p - 1, axis)) < v) exit
        p = p - 1
      end do
      if (p == lo) then
        p = mid + 1
        do while (p <= hi)
          if (graph%xy_local(axis, graph%sorted(p, axis)) > v) exit
          p = p + 1
        end do
      end if
    end function cut_at

    !> For the cut of the current set (label seg) before position p of graph%sorted(:, axis): how
    !! many of the nodes graph%sorted(i0, axis), graph%sorted(i0 + step, axis), ... (towards i1, from the
    !! cut outwards, stopping one edge extent away from it) have a neighbour on the other
    !! side; with sep > 0 those nodes are labelled sep (the separator).
    integer function touching(i0, i1, step, axis, p, sep) result(cnt)
      integer, intent(in) :: i0, i1, step, axis, p, sep
      integer :: i, node, kk, nb, seg
      real(wp) :: cut
      cnt = 0
      if ((i1 - i0)*step < 0) return
      seg = graph%label(graph%sorted(i0, axis))
      if (sep > 0) seg = -1                  ! labels already split: the other side is lset/rset
      cut = graph%xy_local(axis, graph%sorted(i0, axis))
      do i = i0, i1, step
        node = graph%sorted(i, axis)
        if (abs(graph%xy_local(axis, node) - cut) > graph%edge_extent(axis)) exit
        do kk = graph%xadj(node) + 1, graph%xadj(node + 1)
          nb = graph%adj(kk)
          if (sep > 0) then
            if (graph%label(nb) /= sep - 2 .and. graph%label(nb) /= sep - 1) cycle   ! not in this set
            if (graph%label(nb) == sep - 2 .eqv. step > 0) then
              cnt = cnt + 1
              graph%label(node) = sep
              exit
            end if
          else
            if (graph%label(nb) /= seg) cycle
            if ((graph%position(nb, axis) < p) .eqv. step > 0) then
              cnt = cnt + 1
              exit
            end if
          end if
        end do
      end do
    end function touching

  end subroutine coordinate_bisection

  !> METIS nested dissection of the node graph of a stiffness pattern, for the free DOFs not
  !! in `last` (a solid body's interior; the caller puts `last` after them): the nodes of
  !! node_groups, the graph of the nodes they couple through the pattern (DOFs in `last` left
  !! out) ordered by METIS (cm_metis_order, postordered), each node expanded to its DOFs in
  !! increasing order. perm(k) is the free DOF (1-based) placed k-th, size n - size(last),
  !! each node's DOFs consecutive in it. Cost: O(nnz) and METIS on the node graph. On
  !! failure (`last` out of range or repeated, a pattern out of range, METIS failing)
  !! ERR_NUMERICAL or ERR_MEMORY with a sentence, perm empty.
  subroutine node_dissection(colptr, rowind, last, perm, err)
    integer, intent(in) :: colptr(:)                  !< (n+1) 0-based CSC column pointers of the stiffness (both triangles)
    integer, intent(in) :: rowind(:)                  !< 0-based row indices, sorted in each column
    integer, intent(in) :: last(:)                    !< 1-based free DOFs to leave out (ordered last by the caller)
    integer, allocatable, intent(out) :: perm(:)      !< the interior order, 1-based free DOFs
    type(error_t), intent(out) :: err                 !< the failure (perm empty), if any
    type(order_t) :: order
    integer, allocatable :: group_of(:), members(:), gptr(:), gp(:), gi(:), gorder(:), mark(:)
    integer :: n, ng, g, h, k, p, q, st, pass

    n = size(colptr) - 1
    if (n < 0) then
      call err%set(ERR_NUMERICAL, 'node ordering: no column pointers.')
    else
      call start_order(n, last, order, err)
    end if
    if (.not. err%failed()) call node_groups(colptr, rowind, order%skip, group_of, members, gptr, ng, err)
    if (err%failed()) then
      call hand_over(order, err, perm)
      return
    end if

    ! the node graph, strictly upper triangle (CSC, 0-based): node h < g coupled with g. The
    ! rows of a column are sorted and the nodes number the DOFs in increasing order, so a
    ! column's nodes come sorted (DOFs in `last`, node 0, skipped); mark(h) = g: h counted.
    allocate (gp(ng + 1), mark(ng), gorder(max(ng, 1)), stat=st)
    if (st == 0) then
      do pass = 1, 2            ! 1: count, 2: store
        mark = 0
        gp(1) = 0
        do g = 1, ng
          k = gp(g)
          p = members(gptr(g))   ! the node's first DOF: its column is every DOF's of the node
          do q = colptr(p) + 1, colptr(p + 1)
            h = group_of(rowind(q) + 1)
            if (h == 0 .or. h >= g) cycle
            if (mark(h) == g) cycle
            mark(h) = g
            k = k + 1
            if (pass == 2) gi(k) = h - 1
          end do
          gp(g + 1) = k
        end do
        if (pass == 1) then
          allocate (gi(max(1, gp(ng + 1))), stat=st)
          if (st /= 0) exit
          gi = 0
        end if
      end do
    end if
    if (st /= 0) then
      allocate (perm(0))
      call err%set(ERR_MEMORY, 'node ordering: out of memory for the node graph.')
      return
    end if

    call cm_metis_order(ng, gp, gi, gorder, err)
    if (err%failed()) then
      allocate (perm(0))
      return
    end if
    do k = 1, ng
      g = gorder(k) + 1
      do p = gptr(g), gptr(g + 1) - 1
        order%pos = order%pos + 1
        if (order%pos <= size(order%perm)) order%perm(order%pos) = members(p)
      end do
    end do
    call finish_order(order, err)
    call hand_over(order, err, perm)
  end subroutine node_dissection

  !> The nodes of a stiffness pattern (see the module header): the free DOFs not skipped, in
  !! increasing order (members), split into runs (node g: members(gptr(g) : gptr(g+1) - 1)) of
  !! DOFs whose columns, and those of every DOF between them (skipped ones too), are
  !! identical, spanning at most NCOMP consecutive DOFs; group_of(j) is DOF j's node, 0 for a
  !! skipped one. On a pattern out of range ERR_NUMERICAL with a sentence, ng = -1.
  subroutine node_groups(colptr, rowind, skip, group_of, members, gptr, ng, err)
    integer, intent(in) :: colptr(:)                  !< (n+1) 0-based CSC column pointers
    integer, intent(in) :: rowind(:)                  !< 0-based row indices, sorted in each column
    logical, intent(in) :: skip(:)                    !< (n) the DOFs left out (ordered last)
    integer, allocatable, intent(out) :: group_of(:)  !< (n) each DOF's node, 0 if skipped
    integer, allocatable, intent(out) :: members(:)   !< the DOFs not skipped, in increasing order
    integer, allocatable, intent(out) :: gptr(:)      !< (ng+1) node g's DOFs in members
    integer, intent(out) :: ng                        !< the number of nodes, -1 on a bad pattern
    type(error_t), intent(out) :: err                 !< the failure, if any
    integer :: n, j, i, prev, first, nm, q
    logical :: join
    character(len=200) :: emsg

    n = size(colptr) - 1
    ng = -1
    if (n < 0 .or. size(skip) < n) then
      allocate (group_of(0), members(0), gptr(1))
      call err%set(ERR_NUMERICAL, 'node ordering: no column pointers, or fewer skip flags than DOFs.')
      return
    end if
    allocate (group_of(n), members(count(.not. skip(1:n))), gptr(n + 1))
    if (colptr(1) /= 0 .or. colptr(n + 1) > size(rowind)) then
      call err%set(ERR_NUMERICAL, 'node ordering: the column pointers do not start at 0 or exceed the row indices.')
      return
    end if
    do j = 1, n
      if (colptr(j + 1) < colptr(j)) then
        write (emsg, '(a,i0,a)') 'node ordering: the column pointers decrease at column ', j, '.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      do q = colptr(j) + 1, colptr(j + 1)
        if (rowind(q) < 0 .or. rowind(q) >= n) then
          write (emsg, '(a,i0,a,i0,a)') 'node ordering: row index ', rowind(q), ' of column ', j, &
            ' is out of range.'
          call err%set(ERR_NUMERICAL, emsg)
          return
        end if
      end do
    end do
    ng = 0
    nm = 0
    prev = 0
    first = 0
    group_of = 0
    do j = 1, n
      if (skip(j)) cycle
      join = prev > 0 .and. j - first < NCOMP
      if (join) then
        do i = prev + 1, j
          join = same_column(i - 1, i)
          if (.not. join) exit
        end do
      end if
      if (.not. join) then
        ng = ng + 1
        gptr(ng) = nm + 1
        first = j
      end if
      nm = nm + 1
      members(nm) = j
      group_of(j) = ng
      prev = j
    end do
    gptr(ng + 1) = nm + 1

  contains

    !> Whether columns a and b have the same rows.
    logical function same_column(a, b) result(same)
      integer, intent(in) :: a, b
      integer :: la
      la = colptr(a + 1) - colptr(a)
      same = la == colptr(b + 1) - colptr(b)
      if (same) same = all(rowind(colptr(a) + 1:colptr(a + 1)) == rowind(colptr(b) + 1:colptr(b + 1)))
    end function same_column

  end subroutine node_groups

  !> Check `last` (in 1..n, no repeats: else ERR_NUMERICAL with a sentence) and start an
  !! empty order of n - size(last) DOFs.
  subroutine start_order(n, last, order, err)
    integer, intent(in) :: n, last(:)
    type(order_t), intent(out) :: order
    type(error_t), intent(out) :: err
    character(len=200) :: emsg
    integer :: k
    allocate (order%skip(max(n, 0)))
    order%skip = .false.
    do k = 1, size(last)
      if (last(k) < 1 .or. last(k) > n) then
        write (emsg, '(a,i0,a,i0,a)') 'nested dissection: interface DOF ', last(k), ' (entry ', k, ') is out of range.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      else if (order%skip(last(k))) then
        write (emsg, '(a,i0,a,i0,a)') 'nested dissection: interface DOF ', last(k), ' (entry ', k, ') is repeated.'
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      order%skip(last(k)) = .true.
    end do
    allocate (order%perm(n - size(last)))
  end subroutine start_order

  !> Every DOF placed exactly once, else free_of is not a bijection onto 1..n: ERR_NUMERICAL.
  subroutine finish_order(order, err)
    type(order_t), intent(in) :: order
    type(error_t), intent(inout) :: err
    character(len=200) :: emsg
    if (order%bad_map .or. order%pos /= size(order%perm)) then
      write (emsg, '(a,i0,a,i0,a)') 'nested dissection: ordered ', order%pos, ' DOFs but expected ', size(order%perm), &
        ' (inconsistent free-DOF map).'
      call err%set(ERR_NUMERICAL, emsg)
    end if
  end subroutine finish_order

  !> The result: the order, or on failure (err set) an empty perm.
  subroutine hand_over(order, err, perm)
    type(order_t), intent(inout) :: order
    type(error_t), intent(in) :: err
    integer, allocatable, intent(out) :: perm(:)
    if (err%failed()) then
      allocate (perm(0))
    else
      call move_alloc(order%perm, perm)
    end if
  end subroutine hand_over

  !> The other coordinate axis: 2 for 1 (x), 1 for 2 (y).
  pure integer function other_axis(axis)
    integer, intent(in) :: axis
    other_axis = 3 - axis
  end function other_axis

  !> Append the free, non-skipped DOFs of one node (x then y).
  subroutine emit_node(order, free_of, n, node)
    type(order_t), intent(inout) :: order
    integer, intent(in) :: free_of(:), n, node
    integer :: c, f
    do c = 1, NCOMP
      f = free_of(node_dof(node, c))
      if (f <= 0) cycle
      if (f > n) then
        order%bad_map = .true.
        cycle
      end if
      if (order%skip(f)) cycle
      order%pos = order%pos + 1
      if (order%pos <= size(order%perm)) order%perm(order%pos) = f
    end do
  end subroutine emit_node

  !> The arrays a general mesh needs are there and agree in size (else a sentence in emsg).
  logical function general_arrays_ok(xy, free_of, dof_of, colptr, rowind, emsg) result(ok)
    real(wp), intent(in) :: xy(:, :)
    integer, intent(in) :: free_of(:), dof_of(:), colptr(:), rowind(:)
    character(len=*), intent(inout) :: emsg
    integer :: ndof, nnode, n
    ndof = size(free_of)
    nnode = size(xy, 2)
    n = size(dof_of)             ! the free DOFs
    ok = .false.
    if (nnode < 1 .or. ndof /= 2*nnode) then
      write (emsg, '(a,i0,a,i0,a)') 'nested dissection: the system (', ndof, &
        ' DOFs) does not belong to a mesh of ', nnode, ' nodes.'
    else if (size(xy, 1) /= 2) then
      emsg = 'nested dissection: the node coordinates are not (x, y) pairs.'
    else if (size(colptr) /= n + 1) then
      emsg = 'nested dissection: the column pointers do not match the DOF map (size n + 1).'
    else if (colptr(n + 1) > size(rowind)) then
      emsg = 'nested dissection: the stiffness pattern has fewer row indices than its column pointers say.'
    else
      ok = .true.
    end if
  end function general_arrays_ok

  !> The node graph of a general mesh: the ordered nodes (those with a free DOF not in
  !! `last`) renumbered 1..na by increasing x (graph%mesh_node: local -> mesh node, so that the
  !! graph sweeps touch memory in order), their coordinates graph%xy_local, their neighbours
  !! through the stiffness (graph%xadj, graph%adj; both DOFs merged, DOFs in `last` left out), the
  !! largest edge extents graph%edge_extent, the nodes sorted by x (graph%sorted(:,1)) and by y (graph%sorted(:,2)).
  !! .false. with a sentence in emsg on a pattern or DOF map out of range.
  logical function build_node_graph(xy, free_of, dof_of, colptr, rowind, n, skip, graph, emsg) result(ok)
    real(wp), intent(in) :: xy(:, :)
    integer, intent(in) :: free_of(:), dof_of(:), colptr(:), rowind(:), n
    logical, intent(in) :: skip(:)
    type(node_graph_t), intent(out) :: graph
    character(len=*), intent(inout) :: emsg
    integer, allocatable :: mark(:), loc(:)
    integer :: nn, node, c, p, q, kk, nb, cnt, na, pass, i
    logical, allocatable :: active(:)

    ok = .false.
    nn = size(xy, 2)
    allocate (active(nn), loc(nn))
    active = .false.
    do p = 1, n
      if (dof_of(p) < 1 .or. dof_of(p) > size(free_of)) then
        write (emsg, '(a,i0,a,i0,a)') 'nested dissection: free DOF ', p, ' maps to global DOF ', &
          dof_of(p), ', out of range.'
        return
      end if
      if (.not. skip(p)) active((dof_of(p) + 1)/2) = .true.
    end do
    na = count(active)
    allocate (graph%sorted(na, 2), graph%work(na), graph%label(na), mark(na), graph%xadj(na + 1), &
              graph%xy_local(2, na), graph%position(na, 2))
    graph%mesh_node = pack([(node, node=1, nn)], active)
    call sort_nodes(graph%mesh_node, 1, xy)
    loc = 0
    loc(graph%mesh_node) = [(i, i=1, na)]
    graph%xy_local = xy(:, graph%mesh_node)
    graph%label = 0

    do pass = 1, 2            ! 1: count the neighbours, 2: store them
      mark = 0
      graph%xadj(1) = 0
      do i = 1, na
        node = graph%mesh_node(i)
        cnt = graph%xadj(i)
        do c = 1, NCOMP
          p = free_of(node_dof(node, c))
          if (p < 1 .or. p > n) cycle
          if (skip(p)) cycle
          do kk = colptr(p) + 1, colptr(p + 1)
            q = rowind(kk) + 1
            if (q < 1 .or. q > n) then
              write (emsg, '(a,i0,a,i0,a)') 'nested dissection: row index ', q - 1, &
                ' of free DOF ', p, ' is out of range.'
              return
            end if
            if (skip(q)) cycle
            nb = loc((dof_of(q) + 1)/2)
            if (nb == i .or. nb == 0) cycle
            if (mark(nb) == i) cycle
            mark(nb) = i
            cnt = cnt + 1
            if (pass == 2) graph%adj(cnt) = nb
          end do
        end do
        if (pass == 1) then
          graph%xadj(i + 1) = cnt
        else if (cnt /= graph%xadj(i + 1)) then
          emsg = 'nested dissection: internal error building the node graph.'
          return
        end if
      end do
      if (pass == 1) allocate (graph%adj(graph%xadj(na + 1)))
    end do

    graph%edge_extent = 0.0_wp
    do i = 1, na
      do kk = graph%xadj(i) + 1, graph%xadj(i + 1)
        graph%edge_extent = max(graph%edge_extent, abs(graph%xy_local(:, graph%adj(kk)) - graph%xy_local(:, i)))
      end do
    end do
    graph%edge_extent = graph%edge_extent*(1.0_wp + 1.0e-10_wp)        ! no node lost to rounding at the band's edge
    graph%sorted(:, 1) = [(i, i=1, na)]
    graph%sorted(:, 2) = graph%sorted(:, 1)
    call sort_nodes(graph%sorted(:, 2), 2, graph%xy_local)
    ok = .true.
  end function build_node_graph

  !> Stable merge sort of the points ids by coordinate `axis` of xyc, then by the other.
  subroutine sort_nodes(ids, axis, xyc)
    integer, intent(inout) :: ids(:)
    integer, intent(in) :: axis
    real(wp), intent(in) :: xyc(:, :)
    integer, allocatable :: buf(:)
    integer :: width, lo, mid, hi, i, j, k, n
    logical :: first
    n = size(ids)
    allocate (buf(n))
    width = 1
    do while (width < n)
      lo = 1
      do while (lo <= n - width)
        mid = lo + width - 1
        hi = min(lo + 2*width - 1, n)
        i = lo
        j = mid + 1
        k = lo
        do while (i <= mid .and. j <= hi)
          ! point ids(j) strictly before ids(i)?
          if (xyc(axis, ids(j)) /= xyc(axis, ids(i))) then
            first = xyc(axis, ids(j)) < xyc(axis, ids(i))
          else
            first = xyc(other_axis(axis), ids(j)) < xyc(other_axis(axis), ids(i))
          end if
          if (first) then
            buf(k) = ids(j)
            j = j + 1
          else
            buf(k) = ids(i)
            i = i + 1
          end if
          k = k + 1
        end do
        if (i <= mid) buf(k:hi) = ids(i:mid)
        if (j <= hi) buf(k:hi) = ids(j:hi)
        ids(lo:hi) = buf(lo:hi)
        lo = lo + 2*width
      end do
      width = 2*width
    end do
  end subroutine sort_nodes

end module ordering
