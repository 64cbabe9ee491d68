!> Dual mortar coupling of a non-matching or curved two-body contact interface in 2D, the
!! plane implementation of module mortar's contract (`mortar_t`, module mortar_rows)
!! (METHOD.md, "Non-matching and curved interfaces"). Pure geometry: from the slave and
!! master contact edges it builds, per slave node that carries a multiplier, the weighted
!! normal gap constraint
!!
!!     sum_k ws_k n_j.u^s_k - sum_l wm_l n_j.u^m_l <= g0_j,
!!     ws_k = int Phi_j N_k ds / D_jj,  wm_l = M_jl / D_jj = int Phi_j (N^m_l o pi) ds / D_jj,
!!
!! with D_jj = int N_j ds (tributary length), N_k the slave hat functions, Phi_j their dual
!! functions (Phi_1 = (1 - 3 xi)/2, Phi_2 = (1 + 3 xi)/2 on a segment, xi in [-1, 1]) and pi
!! the projection along the slave normal onto the master curve. Rules as implemented (the
!! chains and the projection of master nodes in module mortar_chains):
!!
!! - Chains. Each side's edges must form one open chain or one closed loop (a rim, a bore;
!!   linked by shared nodes through a node -> edge map, O(n)); a branching node, inconsistent
!!   orientation, more than one chain, a zero-length edge or a fold-back (two adjacent edges
!!   reversing) is bad input. A loop is walked as a chain whose last node is its first: that
!!   node has both its edges (normal, dual function, row), and a master segment across it is
!!   clipped in two pieces, one at each end of the chain. Orientation: the body lies on the left of each edge, so an edge's
!!   outward normal is (dy, -dx)/len.
!! - Nodal normals. At an interior slave node, the sum of the two adjacent edges' unit
!!   normals weighted by the inverse edge length, normalised: this is the normal of the
!!   circle through the node and its two neighbours, so for a polygon inscribed in a
!!   circle it is exactly radial whatever the spacing (the unweighted mean is only for
!!   uniform spacing). An end node takes its only edge's normal.
!! - Projection. Along the slave normal field n(xi) interpolated linearly between the two
!!   nodal normals of a slave segment: a master node x is placed at the xi where
!!   (x - x_s(xi)) x n(xi) = 0 (a quadratic), a slave Gauss point at the master point hit
!!   by the line along its n(xi) (linear). The field is continuous from segment to segment,
!!   so the projected master nodes tile the slave curve without gaps or overlaps at slave
!!   kinks (the segment's own normal would leave both at a kink). On a flat slave both are
!!   the same. The slave segment of a master node is found by walking along the slave chain
!!   from the previous master node's segment (the sign of (x - x_i) x n_i changes once along
!!   the chain), O(n_s + n_m) for one chain against another.
!! - Clipping and quadrature. Each master segment maps to an interval of the slave chain;
!!   its pieces on the slave segments are integrated with 5 Gauss points (exact to degree 9:
!!   the flat integrand is of degree 2, the curved one is rational and 5 points put the
!!   quadrature error far below the polygon's). A piece whose master segment does not face
!!   the slave normal (cosine of the angle between n_s and -n_m below 1e-3) is dropped
!!   (the back of a curved master, or a reversed edge list).
!! - Coverage and removed nodes. A slave node is covered when a kept piece reaches it
!!   (within 1e-10 in xi). A node carries a row when it is covered and not `removable`.
!!   A node without a row makes its neighbours' dual functions 1 on the segment they share
!!   with it, so the remaining Phi still sum to one; the neighbour's row then has an extra
!!   slave entry for that node, (int of N_r over the covered part of the segment)/D_jj,
!!   which is (L/2)/D_jj when the segment is covered. D_jj stays int N_j over the whole
!!   support.
!! - Partial overlap (a master end inside a slave segment). Both sides of a row are
!!   integrated over the covered part only: on a partly covered segment the slave weights
!!   are int_cov Phi_j N_k / D_jj (numerically, so the own weight of such an end row is
!!   below 1), on covered segments they are exact (own weight 1). So every row satisfies
!!   sum ws = sum wm (invariant under rigid translation) and g0 is the weighted gap of the
!!   geometry, independent of the origin. A row whose master weight sum is below 1e-3 is
!!   dropped as not covered (its neighbours' functions are modified as above, and the rows
!!   are rebuilt); with a single facing chain this does not happen (the own covered segment
!!   gives at least about 1/2).
!! - g0_j = sum_l wm_l n_j.(x^m_l - x^s_j) - sum_k ws_k n_j.(x^s_k - x^s_j): the row at u = 0
!!   for the gap function g(x) = (x^m(pi(x)) - x).n_j, i.e. int Phi_j g ds / D_jj, written
!!   relative to x^s_j (the same value, since the weight sums agree, with less rounding for
!!   large coordinates). It includes the extra slave entries (METHOD.md's G0 has only x^s_j,
!!   the same where a row has no extra entry). A uniform gap h gives g0 = h times the row's
!!   weight sum: h where the row is the plain one, more next to a removed node, less at a
!!   partly covered end.
module mortar_segments
  use kinds, only: wp
  use strings, only: i2s
  use errors, only: error_t, ERR_INPUT
  use mortar_rows, only: mortar_t
  use mortar_chains, only: chain_order, project_master_nodes, edge_normal, cross, UNPLACED
  implicit none (type, external)
  private

  public :: segment_mortar

  integer, parameter :: NGAUSS = 5
  real(wp), parameter :: GZ(NGAUSS) = [-0.9061798459386639927976269_wp, -0.5384693101056830910363144_wp, 0.0_wp, &
                                       0.5384693101056830910363144_wp, 0.9061798459386639927976269_wp]
  real(wp), parameter :: GW(NGAUSS) = [0.2369268850561890875142640_wp, 0.4786286704993664680412915_wp, &
                                       0.5688888888888888888888889_wp, 0.4786286704993664680412915_wp, &
                                       0.2369268850561890875142640_wp]
  real(wp), parameter :: TOL_COVER = 1.0e-10_wp    ! a piece this close (in xi) to a node covers it
  real(wp), parameter :: TOL_FULL = 1.0e-12_wp     ! relative shortfall of a segment still counted as covered
  real(wp), parameter :: MIN_FACING = 1.0e-3_wp    ! cosine between n_s and -n_m below which a piece is dropped
  real(wp), parameter :: MIN_WEIGHT = 1.0e-3_wp    ! a row whose master weights sum below this is dropped

  !> The work of one mortar_build: the two chains, the slave geometry, where the master
  !! nodes fall on the slave chain, the clipped pieces and which slave nodes carry rows.
  type :: mortar_work_t
    integer :: nes = 0, nem = 0                 ! slave and master edges
    integer, allocatable :: cs(:), cm(:)        ! (0:ne) slave and master nodes in chain order
    logical :: closed = .false.                 ! the slave chain is a closed loop
    logical :: axisym = .false.                 ! meridian sections: every integral weighted by r = x
    real(wp), allocatable :: slen(:)            ! (nes) slave segment lengths
    real(wp), allocatable :: arc(:)             ! (0:nes) arc length of the slave chain nodes
    real(wp), allocatable :: nn(:, :)           ! (2, 0:nes) slave nodal unit normals
    integer, allocatable :: mstat(:), mseg(:)   ! (0:nem) master node place: status, slave segment
    real(wp), allocatable :: mxi(:)             ! (0:nem) and xi on it
    integer :: np = 0, nrej = 0                 ! pieces kept, pieces dropped as not facing
    integer, allocatable :: pk(:), pq(:)        ! piece: slave segment, master segment
    real(wp), allocatable :: plo(:), phi(:)     ! piece: xi interval on its slave segment
    integer, allocatable :: kptr(:), ord(:)     ! pieces grouped by slave segment
    real(wp), allocatable :: covlen(:)          ! (nes) covered length of each segment, in xi
    logical, allocatable :: full(:)             ! (nes) segment covered whole
    logical, allocatable :: covered(:)          ! (0:nes) slave node reached by a piece
    logical, allocatable :: isrow(:)            ! (0:nes) slave node carries a row
  end type mortar_work_t

contains

  !> Build the dual mortar rows of a slave contact chain against a master chain (2D).
  !! err (ERR_INPUT, naming the side and the edge or node) on bad input, or when no slave
  !! node ends up with a row (no overlap, master edges facing away, all removable).
  subroutine segment_mortar(xs, es, removable, xm, em, mt, err, tag_s, tag_m, axisymmetric)
    real(wp), intent(in) :: xs(:, :)        !< (2, nnode_s) slave body node coordinates [length]
    integer, intent(in) :: es(:, :)         !< (2, ne_s) slave contact edges (node ids), slave body on the left of es(1)->es(2)
    logical, intent(in) :: removable(:)     !< (nnode_s) the slave node may carry no multiplier (normal displacement prescribed on both bodies)
    real(wp), intent(in) :: xm(:, :)        !< (2, nnode_m) master body node coordinates [length]
    integer, intent(in) :: em(:, :)         !< (2, ne_m) master contact edges, master body on the left
    type(mortar_t), intent(out) :: mt       !< the constraint rows
    type(error_t), intent(out) :: err       !< the bad input, if any
    integer, intent(in), optional :: tag_s(:), tag_m(:)   !< (nnode_s), (nnode_m) node tags for messages
    !> meridian sections of bodies of revolution (x = r): D, M and the dual functions of the
    !! r-weighted arc length r ds (per radian), the dual basis biorthogonal in it
    logical, intent(in), optional :: axisymmetric
    type(mortar_work_t) :: w
    logical :: mclosed
    integer :: i, iter, nbad

    if (size(xs, 1) /= 2 .or. size(xm, 1) /= 2) then
      call err%set(ERR_INPUT, 'mortar: node coordinates must be (2, nnode) arrays')
      return
    end if
    if (size(removable) /= size(xs, 2)) then
      call err%set(ERR_INPUT, 'mortar: removable has '//i2s(size(removable))//' entries for '//i2s(size(xs, 2))//' slave nodes')
      return
    end if
    if (present(axisymmetric)) w%axisym = axisymmetric
    call chain_order(xs, es, 'slave', w%cs, w%closed, err, tag_s)
    if (err%failed()) return
    call chain_order(xm, em, 'master', w%cm, mclosed, err, tag_m)
    if (err%failed()) return
    w%nes = size(es, 2)
    w%nem = size(em, 2)

    call slave_normals(w, xs, err, tag_s)
    if (err%failed()) return

    ! Each master node's place on the slave chain: segment mseg and xi (mstat 0), or before
    ! the chain's start (mstat -1) or beyond its end (+1).
    allocate (w%mstat(0:w%nem), w%mseg(0:w%nem), w%mxi(0:w%nem))
    call project_master_nodes(xs, w%cs, w%nn, w%closed, xm, w%cm, w%mstat, w%mseg, w%mxi)

    call clip_pieces(w, xm)
    call sort_pieces(w)

    allocate (w%isrow(0:w%nes))
    do i = 0, w%nes
      w%isrow(i) = w%covered(i) .and. .not. removable(w%cs(i))
    end do
    do iter = 1, w%nes + 2
      call build_rows(w, xs, xm, mt, nbad)
      if (nbad == 0) exit
    end do

    if (mt%m == 0) then
      if (w%np == 0 .and. w%nrej > 0) then
        call err%set(ERR_INPUT, 'mortar: every master edge over the slave faces away from it (n_s.n_m >= 0): '// &
                     'both bodies must lie on the left of their edges; is one edge list reversed?')
      else if (w%np == 0) then
        call err%set(ERR_INPUT, 'mortar: the master curve does not overlap the slave curve along the slave normals')
      else
        call err%set(ERR_INPUT, 'mortar: no slave node carries a multiplier (every covered slave node is removable)')
      end if
    end if
  end subroutine segment_mortar

  !> Slave segment lengths, arc length and nodal normals (inverse-length weighted);
  !! err (ERR_INPUT) where the chain folds back on itself.
  subroutine slave_normals(w, xs, err, tag)
    type(mortar_work_t), intent(inout) :: w
    real(wp), intent(in) :: xs(:, :)
    type(error_t), intent(inout) :: err
    integer, intent(in), optional :: tag(:)     !< node tags for messages
    integer :: i, k, nes, nid
    real(wp) :: lo, hi
    nes = w%nes
    allocate (w%slen(nes), w%arc(0:nes), w%nn(2, 0:nes))
    associate (cs => w%cs, slen => w%slen, arc => w%arc, nn => w%nn, closed => w%closed)
      arc(0) = 0.0_wp
      nn = 0.0_wp
      do k = 1, nes
        slen(k) = norm2(xs(:, cs(k)) - xs(:, cs(k - 1)))
        arc(k) = arc(k - 1) + slen(k)
        nn(:, k - 1) = nn(:, k - 1) + edge_normal(xs(:, cs(k - 1)), xs(:, cs(k))) / slen(k)
        nn(:, k) = nn(:, k) + edge_normal(xs(:, cs(k - 1)), xs(:, cs(k))) / slen(k)
      end do
      if (closed) then
        ! the loop's first and last chain nodes are one node, with both its edges
        nn(:, 0) = nn(:, 0) + nn(:, nes)
        nn(:, nes) = nn(:, 0)
      end if
      do i = 0, nes
        lo = 0.0_wp
        if (i > 0 .or. closed) lo = lo + 1.0_wp / slen(merge(i, nes, i > 0))
        if (i < nes .or. closed) lo = lo + 1.0_wp / slen(merge(i + 1, 1, i < nes))
        hi = norm2(nn(:, i))
        if (hi <= 1.0e-8_wp * lo) then
          nid = cs(i)
          if (present(tag)) nid = tag(cs(i))
          call err%set(ERR_INPUT, 'mortar: the slave chain folds back on itself at node '//i2s(nid)//' (its two edges are opposite)')
          return
        end if
        nn(:, i) = nn(:, i) / hi
      end do
    end associate
  end subroutine slave_normals

  !> Clip: each master segment covers a slave interval; its pieces per slave segment.
  subroutine clip_pieces(w, xm)
    type(mortar_work_t), intent(inout) :: w
    real(wp), intent(in) :: xm(:, :)
    integer :: q, k, i, klo, khi, nes, nem
    real(wp) :: lo, hi, xlo, xhi, sa, sb
    nes = w%nes
    nem = w%nem
    w%np = 0
    w%nrej = 0
    allocate (w%pk(nes + nem + 8), w%pq(nes + nem + 8), w%plo(nes + nem + 8), w%phi(nes + nem + 8))
    do q = 1, nem
      if (w%mstat(q - 1) /= 0 .and. w%mstat(q - 1) == w%mstat(q)) cycle
      if (w%mstat(q - 1) == UNPLACED .or. w%mstat(q) == UNPLACED) cycle
      call place(w, q - 1, k, lo)
      call place(w, q, i, hi)
      if (i < k .or. (i == k .and. hi < lo)) then
        klo = i; xlo = hi; khi = k; xhi = lo
      else
        klo = k; xlo = lo; khi = i; xhi = hi
      end if
      sa = w%arc(klo - 1) + 0.5_wp * (xlo + 1.0_wp) * w%slen(klo)
      sb = w%arc(khi - 1) + 0.5_wp * (xhi + 1.0_wp) * w%slen(khi)
      if (w%closed .and. sb - sa > 0.5_wp * w%arc(nes)) then
        ! the segment straddles the loop's first node: its two ends of the loop
        call add_pieces(w, xm, q, khi, xhi, nes, 1.0_wp)
        call add_pieces(w, xm, q, 1, -1.0_wp, klo, xlo)
      else
        call add_pieces(w, xm, q, klo, xlo, khi, xhi)
      end if
    end do
  end subroutine clip_pieces

  !> Pieces grouped by slave segment (counting sort), coverage of segments and nodes.
  subroutine sort_pieces(w)
    type(mortar_work_t), intent(inout) :: w
    integer, allocatable :: fill(:)
    integer :: i, k, nes, np
    nes = w%nes
    np = w%np
    allocate (w%kptr(nes + 1), w%ord(np), w%covlen(nes), w%full(nes), w%covered(0:nes))
    associate (kptr => w%kptr, ord => w%ord, covlen => w%covlen, covered => w%covered, pk => w%pk, &
               plo => w%plo, phi => w%phi)
      kptr = 0
      do i = 1, np
        kptr(pk(i) + 1) = kptr(pk(i) + 1) + 1
      end do
      kptr(1) = 1
      do k = 1, nes
        kptr(k + 1) = kptr(k + 1) + kptr(k)
      end do
      covlen = 0.0_wp
      covered = .false.
      allocate (fill(nes))
      fill = kptr(1:nes)
      do i = 1, np
        k = pk(i)
        ord(fill(k)) = i
        fill(k) = fill(k) + 1
        covlen(k) = covlen(k) + (phi(i) - plo(i))
        if (plo(i) <= -1.0_wp + TOL_COVER) covered(k - 1) = .true.
        if (phi(i) >= 1.0_wp - TOL_COVER) covered(k) = .true.
      end do
      w%full = covlen >= 2.0_wp * (1.0_wp - TOL_FULL)
      if (w%closed) then
        covered(0) = covered(0) .or. covered(nes)
        covered(nes) = covered(0)
      end if
    end associate
  end subroutine sort_pieces

  !> The pieces of master segment qq on the slave chain from (k1, x1) to (k2, x2), one per
  !! slave segment, those that face the slave normal.
  subroutine add_pieces(w, xm, qq, k1, x1, k2, x2)
    type(mortar_work_t), intent(inout) :: w
    real(wp), intent(in) :: xm(:, :)
    integer, intent(in) :: qq, k1, k2
    real(wp), intent(in) :: x1, x2
    integer :: kk
    real(wp) :: a, b
    do kk = k1, k2
      a = -1.0_wp
      b = 1.0_wp
      if (kk == k1) a = x1
      if (kk == k2) b = x2
      if (b <= a) cycle
      if (.not. facing(w, xm, kk, qq, 0.5_wp * (a + b))) then
        w%nrej = w%nrej + 1
        cycle
      end if
      if (w%np == size(w%pk)) call grow(w)
      w%np = w%np + 1
      w%pk(w%np) = kk; w%pq(w%np) = qq; w%plo(w%np) = a; w%phi(w%np) = b
    end do
  end subroutine add_pieces

  !> The slave segment before chain node ii (0: none), across the first node of a loop.
  pure integer function seg_before(w, ii)
    type(mortar_work_t), intent(in) :: w
    integer, intent(in) :: ii
    seg_before = ii
    if (ii == 0 .and. w%closed) seg_before = w%nes
  end function seg_before

  !> Where master chain node p sits on the slave chain, as (segment, xi), ends clamped.
  subroutine place(w, p, kk, xx)
    type(mortar_work_t), intent(in) :: w
    integer, intent(in) :: p
    integer, intent(out) :: kk
    real(wp), intent(out) :: xx
    select case (w%mstat(p))
    case (-1)
      kk = 1; xx = -1.0_wp
    case (1)
      kk = w%nes; xx = 1.0_wp
    case default
      kk = w%mseg(p); xx = w%mxi(p)
    end select
  end subroutine place

  !> Does master segment qq face the slave normal of segment kk at xi?
  logical function facing(w, xm, kk, qq, xi)
    type(mortar_work_t), intent(in) :: w
    real(wp), intent(in) :: xm(:, :)
    integer, intent(in) :: kk, qq
    real(wp), intent(in) :: xi
    real(wp) :: ns(2), nm(2)
    ns = 0.5_wp * (1.0_wp - xi) * w%nn(:, kk - 1) + 0.5_wp * (1.0_wp + xi) * w%nn(:, kk)
    nm = edge_normal(xm(:, w%cm(qq - 1)), xm(:, w%cm(qq)))
    facing = dot_product(ns, nm) < -MIN_FACING * norm2(ns) * norm2(nm)
  end function facing

  !> Double the capacity of the piece arrays.
  subroutine grow(w)
    type(mortar_work_t), intent(inout) :: w
    integer, allocatable :: ti(:)
    real(wp), allocatable :: tr(:)
    integer :: nw, np
    np = w%np
    nw = 2 * size(w%pk)
    allocate (ti(nw)); ti(1:np) = w%pk(1:np); call move_alloc(ti, w%pk)
    allocate (ti(nw)); ti(1:np) = w%pq(1:np); call move_alloc(ti, w%pq)
    allocate (tr(nw)); tr(1:np) = w%plo(1:np); call move_alloc(tr, w%plo)
    allocate (tr(nw)); tr(1:np) = w%phi(1:np); call move_alloc(tr, w%phi)
  end subroutine grow

  !> Fill mt from isrow; rows whose master weights sum below MIN_WEIGHT are switched off
  !! (nbad of them), in which case the caller builds again.
  subroutine build_rows(wk, xs, xm, mt, nbad)
    type(mortar_work_t), intent(inout) :: wk   !< the chains, normals and pieces; isrow is updated
    real(wp), intent(in) :: xs(:, :), xm(:, :)
    type(mortar_t), intent(inout) :: mt
    integer, intent(out) :: nbad
    integer :: j, m, cap, ns_, nm_, side, kk, other, ii, g, l, l1, l2, e, e2, pc, s0, m0_, nlast
    integer, allocatable :: pos(:)
    real(wp) :: dj, ws(-1:1), xa(2), xb(2), c0(2), c1(2), mm0(2), mm1(2), p1(2), dq(2), half, mid, xi, w, &
                ph, p(2), ng(2), den, t, sw, g0, rj, ro, aown, aoth, det
    logical :: dual, isb

    associate (nes => wk%nes, closed => wk%closed, cs => wk%cs, cm => wk%cm, nn => wk%nn, slen => wk%slen, &
               arc => wk%arc, kptr => wk%kptr, ord => wk%ord, pq => wk%pq, plo => wk%plo, phi => wk%phi, &
               full => wk%full, isrow => wk%isrow)
      nlast = merge(nes - 1, nes, closed)      ! a loop's last chain node is its first
      m = count(isrow(0:nlast))
      cap = 0
      do ii = 0, nlast
        if (.not. isrow(ii)) cycle
        kk = seg_before(wk, ii)
        if (kk > 0) cap = cap + 2 * (kptr(kk + 1) - kptr(kk))
        if (ii < nes) cap = cap + 2 * (kptr(ii + 2) - kptr(ii + 1))
      end do
      mt%m = m
      if (allocated(mt%snode)) deallocate (mt%snode, mt%normal, mt%d, mt%s, mt%g0, mt%sptr, mt%snod, mt%sval, &
                                           mt%mptr, mt%mnod, mt%mval)
      allocate (mt%snode(m), mt%normal(2, m), mt%d(m), mt%s(m), mt%g0(m), mt%sptr(m + 1), mt%snod(3 * m), &
                mt%sval(3 * m), mt%mptr(m + 1), mt%mnod(cap), mt%mval(cap))
      allocate (pos(size(xm, 2)))
      pos = 0
      nbad = 0
      j = 0
      ns_ = 0
      nm_ = 0
      do ii = 0, nlast
        if (.not. isrow(ii)) cycle
        j = j + 1
        mt%snode(j) = cs(ii)
        mt%normal(:, j) = nn(:, ii)
        mt%s(j) = arc(ii)
        mt%sptr(j) = ns_ + 1
        mt%mptr(j) = nm_ + 1
        m0_ = nm_
        dj = 0.0_wp
        ws = 0.0_wp
        do side = -1, 1, 2
          ! side -1: segment ii (nodes ii-1, ii; this node is its end b); +1: segment ii+1 (node a).
          if (side == -1) then
            kk = seg_before(wk, ii)
            if (kk == 0) cycle
          else
            if (ii == nes) cycle
            kk = ii + 1
          end if
          isb = side == -1
          other = ii + side
          if (other < 0) other = nes - 1
          dual = isrow(other)
          xa = xs(:, cs(kk - 1)); xb = xs(:, cs(kk))
          if (wk%axisym) then
            ! r-weighted: int N_j r ds = L/6 (2 r_j + r_o); the dual function of this node on the
            ! segment Phi_j = aown N_j + aoth N_o, the row of D_e M_e^-1 (M_e the segment's
            ! r-weighted mass matrix, D_e its row sums): (2, -1) where r is constant
            rj = merge(xb(1), xa(1), isb)
            ro = merge(xa(1), xb(1), isb)
            dj = dj + slen(kk) / 6.0_wp * (2.0_wp * rj + ro)
            if (full(kk)) then
              ws(0) = ws(0) + slen(kk) / 6.0_wp * (2.0_wp * rj + ro)
              if (.not. dual) ws(side) = ws(side) + slen(kk) / 6.0_wp * (rj + 2.0_wp * ro)
            end if
            det = 2.0_wp * rj * rj + 8.0_wp * rj * ro + 2.0_wp * ro * ro
            if (det > 0.0_wp) then
              aown = 2.0_wp * (2.0_wp * rj + ro) * (rj + 3.0_wp * ro) / det
              aoth = -2.0_wp * (2.0_wp * rj + ro) * (rj + ro) / det
            else                     ! a segment on the axis: r = 0, it adds nothing
              aown = 2.0_wp
              aoth = -1.0_wp
            end if
          else
            dj = dj + 0.5_wp * slen(kk)
            if (full(kk)) then
              ws(0) = ws(0) + 0.5_wp * slen(kk)
              if (.not. dual) ws(side) = ws(side) + 0.5_wp * slen(kk)
            end if
          end if
          c0 = 0.5_wp * (xa + xb); c1 = 0.5_wp * (xb - xa)
          mm0 = 0.5_wp * (nn(:, kk - 1) + nn(:, kk)); mm1 = 0.5_wp * (nn(:, kk) - nn(:, kk - 1))
          do e = kptr(kk), kptr(kk + 1) - 1
            pc = ord(e)
            l1 = cm(pq(pc) - 1); l2 = cm(pq(pc))
            p1 = xm(:, l1); dq = xm(:, l2) - p1
            half = 0.5_wp * (phi(pc) - plo(pc))
            mid = 0.5_wp * (phi(pc) + plo(pc))
            do g = 1, NGAUSS
              xi = mid + half * GZ(g)
              w = GW(g) * half * 0.5_wp * slen(kk)
              if (.not. dual) then
                ph = 1.0_wp
              else if (wk%axisym .and. isb) then
                ph = aown * 0.5_wp * (1.0_wp + xi) + aoth * 0.5_wp * (1.0_wp - xi)
              else if (wk%axisym) then
                ph = aown * 0.5_wp * (1.0_wp - xi) + aoth * 0.5_wp * (1.0_wp + xi)
              else if (isb) then
                ph = 0.5_wp * (1.0_wp + 3.0_wp * xi)
              else
                ph = 0.5_wp * (1.0_wp - 3.0_wp * xi)
              end if
              p = c0 + xi * c1
              if (wk%axisym) w = w * p(1)
              ng = mm0 + xi * mm1
              den = cross(dq, ng)
              if (den /= 0.0_wp) then
                t = min(1.0_wp, max(0.0_wp, cross(p - p1, ng) / den))
              else
                t = 0.5_wp
              end if
              do e2 = 1, 2
                l = merge(l1, l2, e2 == 1)
                if (pos(l) == 0) then
                  nm_ = nm_ + 1
                  pos(l) = nm_
                  mt%mnod(nm_) = l
                  mt%mval(nm_) = 0.0_wp
                end if
                mt%mval(pos(l)) = mt%mval(pos(l)) + w * ph * merge(1.0_wp - t, t, e2 == 1)
              end do
              if (.not. full(kk)) then
                ! Partly covered: slave weights over the covered part. N of this node is
                ! (1 + xi)/2 when it is end b of the segment, (1 - xi)/2 when it is end a.
                if (isb) then
                  ws(0) = ws(0) + w * ph * 0.5_wp * (1.0_wp + xi)
                  ws(side) = ws(side) + w * ph * 0.5_wp * (1.0_wp - xi)
                else
                  ws(0) = ws(0) + w * ph * 0.5_wp * (1.0_wp - xi)
                  ws(side) = ws(side) + w * ph * 0.5_wp * (1.0_wp + xi)
                end if
              end if
            end do
          end do
        end do
        mt%d(j) = dj
        ! Slave entries: own node first, then a neighbour with a modified or partly covered function.
        ns_ = ns_ + 1
        mt%snod(ns_) = cs(ii)
        mt%sval(ns_) = ws(0) / dj
        s0 = ns_
        do side = -1, 1, 2
          other = ii + side
          kk = ii + max(side, 0)
          if (other < 0 .and. closed) then
            other = nes - 1
            kk = nes
          end if
          if (other < 0 .or. other > nes) cycle
          if (isrow(other) .and. full(kk)) cycle   ! dual pair on a covered segment: int Phi_j N_other = 0
          if (ws(side) == 0.0_wp) cycle                 ! no covered part on that segment
          ns_ = ns_ + 1
          mt%snod(ns_) = cs(other)
          mt%sval(ns_) = ws(side) / dj
        end do
        ! Master weights / D, the gap relative to the node, and the weight sum.
        sw = 0.0_wp
        g0 = 0.0_wp
        do e = m0_ + 1, nm_
          l = mt%mnod(e)
          pos(l) = 0
          mt%mval(e) = mt%mval(e) / dj
          sw = sw + mt%mval(e)
          g0 = g0 + mt%mval(e) * dot_product(nn(:, ii), xm(:, l) - xs(:, cs(ii)))
        end do
        do e = s0 + 1, ns_
          g0 = g0 - mt%sval(e) * dot_product(nn(:, ii), xs(:, mt%snod(e)) - xs(:, cs(ii)))
        end do
        mt%g0(j) = g0
        if (.not. (sw >= MIN_WEIGHT)) then
          nbad = nbad + 1
          isrow(ii) = .false.
          if (closed .and. ii == 0) isrow(nes) = .false.
        end if
      end do
      mt%sptr(m + 1) = ns_ + 1
      mt%mptr(m + 1) = nm_ + 1
      if (nbad == 0) then
        mt%snod = mt%snod(1:ns_)
        mt%sval = mt%sval(1:ns_)
        mt%mnod = mt%mnod(1:nm_)
        mt%mval = mt%mval(1:nm_)
      end if
    end associate
  end subroutine build_rows

end module mortar_segments
