!> The chains of a mortar interface (METHOD.md, "Non-matching and curved interfaces"):
!! one side's contact edges ordered into one open chain or one closed loop, with the
!! checks on bad input, and the master nodes placed on the slave chain along the slave
!! normal field interpolated between the nodal normals (module mortar builds the rows).
module mortar_chains
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use kinds, only: wp
  use strings, only: i2s
  use errors, only: error_t, ERR_INPUT
  implicit none (type, external)
  private

  public :: chain_order, project_master_nodes, edge_normal, cross

  integer, parameter, public :: UNPLACED = 2       !< mstat of a master node no slave normal line reaches

contains


  !> Order the edges of one side into a single chain: c(0:ne) are its nodes from the start
  !! (the node no edge ends at), edge k joining c(k-1) -> c(k). A closed loop (a rim, a bore)
  !! starts at the first edge's first node and has c(ne) = c(0).
  subroutine chain_order(x, e, what, c, closed, err, tag)
    real(wp), intent(in) :: x(:, :)            !< (2, nnode) coordinates
    integer, intent(in) :: e(:, :)             !< (2, ne) edges
    character(len=*), intent(in) :: what       !< 'slave' or 'master', for messages
    integer, allocatable, intent(out) :: c(:)  !< (0:ne) nodes in chain order
    logical, intent(out) :: closed             !< the edges form one closed loop
    type(error_t), intent(inout) :: err        !< set (ERR_INPUT) on bad input
    integer, intent(in), optional :: tag(:)    !< (nnode) the nodes' tags for messages (default: their numbers)
    integer, allocatable :: eout(:), ein(:), deg(:)
    integer :: ne, nnode, k, a, b, nstart, start, n
    real(wp) :: lo(2), hi(2), diag

    closed = .false.
    ne = size(e, 2)
    nnode = size(x, 2)
    if (size(e, 1) /= 2) then
      call err%set(ERR_INPUT, 'mortar: the '//what//' edges must be a (2, ne) array')
      return
    end if
    if (ne == 0) then
      call err%set(ERR_INPUT, 'mortar: no '//what//' contact edges')
      return
    end if
    do k = 1, ne
      if (any(e(:, k) < 1) .or. any(e(:, k) > nnode)) then
        call err%set(ERR_INPUT, 'mortar: '//what//' edge '//i2s(k)//' refers to node '//i2s(merge(e(1, k), e(2, k), &
              e(1, k) < 1 .or. e(1, k) > nnode))//', outside 1..'//i2s(nnode))
        return
      end if
      if (.not. all(ieee_is_finite(x(:, e(:, k))))) then
        call err%set(ERR_INPUT, 'mortar: '//what//' edge '//i2s(k)//' has a node with a non-finite coordinate')
        return
      end if
    end do
    lo = huge(1.0_wp)
    hi = -huge(1.0_wp)
    do k = 1, ne
      do a = 1, 2
        lo = min(lo, x(:, e(a, k)))
        hi = max(hi, x(:, e(a, k)))
      end do
    end do
    diag = norm2(hi - lo)
    do k = 1, ne
      if (e(1, k) == e(2, k) .or. norm2(x(:, e(2, k)) - x(:, e(1, k))) <= 1.0e-12_wp * diag) then
        call err%set(ERR_INPUT, 'mortar: '//what//' edge '//i2s(k)//' (nodes '//node_name(e(1, k))//', '//node_name(e(2, k))//') has zero length')
        return
      end if
    end do
    allocate (eout(nnode), ein(nnode), deg(nnode))
    eout = 0
    ein = 0
    deg = 0
    do k = 1, ne
      deg(e(:, k)) = deg(e(:, k)) + 1
    end do
    do k = 1, ne
      do a = 1, 2
        if (deg(e(a, k)) > 2) then
          call err%set(ERR_INPUT, 'mortar: the '//what//' edges branch at node '//node_name(e(a, k))//' ('//i2s(deg(e(a, k)))// &
                ' edges meet there); one chain is required')
          return
        end if
      end do
    end do
    do k = 1, ne
      a = e(1, k)
      b = e(2, k)
      if (eout(a) /= 0) then
        call err%set(ERR_INPUT, 'mortar: '//what//' edges '//i2s(eout(a))//' and '//i2s(k)//' both start at node '//node_name(a)// &
              ': they are not consistently oriented (the body must lie on the left of every edge)')
        return
      end if
      if (ein(b) /= 0) then
        call err%set(ERR_INPUT, 'mortar: '//what//' edges '//i2s(ein(b))//' and '//i2s(k)//' both end at node '//node_name(b)// &
              ': they are not consistently oriented (the body must lie on the left of every edge)')
        return
      end if
      eout(a) = k
      ein(b) = k
    end do
    nstart = 0
    start = 0
    do k = 1, ne
      a = e(1, k)
      if (ein(a) == 0) then
        nstart = nstart + 1
        start = a
      end if
    end do
    if (nstart == 0) then
      closed = .true.
      start = e(1, 1)
    end if
    if (nstart > 1) then
      call err%set(ERR_INPUT, 'mortar: the '//what//' edges form '//i2s(nstart)//' separate chains; one chain or one loop is required')
      return
    end if
    allocate (c(0:ne))
    c(0) = start
    n = 0
    do while (eout(c(n)) /= 0)
      if (n == ne) exit
      k = eout(c(n))
      n = n + 1
      c(n) = e(2, k)
      if (closed .and. c(n) == start) exit
    end do
    if (closed .and. n /= ne) then
      call err%set(ERR_INPUT, 'mortar: the '//what//' edges form more than one closed loop (one of '//i2s(n)//' edges, the '// &
            'other '//i2s(ne - n)//'); one chain or one loop is required')
      return
    end if
    if (n /= ne) then
      call err%set(ERR_INPUT, 'mortar: the '//what//' edges form more than one chain (a chain of '//i2s(n)//' edges and a closed '// &
            'loop of the other '//i2s(ne - n)//'); one chain is required')
      return
    end if
  contains
    function node_name(n) result(t)
      integer, intent(in) :: n
      character(len=:), allocatable :: t
      t = i2s(n)
      if (present(tag)) t = i2s(tag(n))
    end function node_name
  end subroutine chain_order

  !> Place every master chain node on the slave chain along the interpolated slave normal:
  !! the segment k where sigma_i = (x - x_i) x n_i changes sign from <= 0 at node k-1 to
  !! >= 0 at node k, found by walking from the previous node's segment. Along the slave
  !! curve sigma grows through the point x projects to (d sigma/ds = 1 + d kappa > 0 while
  !! x is nearer than the centre of curvature), so on a closed slave loop, where the walk
  !! wraps around, the rising sign change is the projection; a node with none is UNPLACED.
  subroutine project_master_nodes(xs, cs, nn, closed, xm, cm, mstat, mseg, mxi)
    real(wp), intent(in) :: xs(:, :), nn(:, 0:), xm(:, :)
    integer, intent(in) :: cs(0:), cm(0:)
    logical, intent(in) :: closed
    integer, intent(out) :: mstat(0:), mseg(0:)
    real(wp), intent(out) :: mxi(0:)
    integer :: nes, k, p, steps
    real(wp) :: x(2)
    nes = size(cs) - 1
    k = nes
    do p = 0, size(cm) - 1
      x = xm(:, cm(p))
      mseg(p) = 0
      mxi(p) = 0.0_wp
      steps = 0
      do
        steps = steps + 1
        if (steps > nes + 2) then
          mstat(p) = UNPLACED
          k = nes
          exit
        end if
        if (cross(x - xs(:, cs(k - 1)), nn(:, k - 1)) > 0.0_wp) then
          if (k == 1) then
            if (closed) then
              k = nes
              cycle
            end if
            mstat(p) = -1
            exit
          end if
          k = k - 1
        else if (cross(x - xs(:, cs(k)), nn(:, k)) < 0.0_wp) then
          if (k == nes) then
            if (closed) then
              k = 1
              cycle
            end if
            mstat(p) = 1
            exit
          end if
          k = k + 1
        else
          mstat(p) = 0
          mseg(p) = k
          mxi(p) = project_on_segment(x, xs(:, cs(k - 1)), xs(:, cs(k)), nn(:, k - 1), nn(:, k))
          exit
        end if
      end do
    end do
  end subroutine project_master_nodes

  !> The xi in [-1, 1] where (x - x_s(xi)) x n(xi) = 0 on the segment xa -> xb with nodal
  !! normals na, nb interpolated linearly (a quadratic; the caller has checked the sign
  !! change between the ends).
  pure real(wp) function project_on_segment(x, xa, xb, na, nb) result(xi)
    real(wp), intent(in) :: x(2), xa(2), xb(2), na(2), nb(2)
    real(wp) :: c0(2), c1(2), m0(2), m1(2), d(2), a, b, c, disc, q, r(2), fl, fm, lo, hi
    integer :: it, i
    c0 = 0.5_wp * (xa + xb)
    c1 = 0.5_wp * (xb - xa)
    m0 = 0.5_wp * (na + nb)
    m1 = 0.5_wp * (nb - na)
    d = x - c0
    a = -cross(c1, m1)
    b = cross(d, m1) - cross(c1, m0)
    c = cross(d, m0)
    ! f(xi) = c + b xi + a xi^2
    if (a == 0.0_wp) then
      if (b /= 0.0_wp) then
        xi = min(1.0_wp, max(-1.0_wp, -c / b))
        return
      end if
    else
      disc = b * b - 4.0_wp * a * c
      if (disc >= 0.0_wp) then
        q = -0.5_wp * (b + sign(sqrt(disc), b))
        r = huge(1.0_wp)
        r(1) = q / a
        if (q /= 0.0_wp) r(2) = c / q
        i = minloc(abs(r), 1)
        if (abs(r(i)) <= 1.0_wp + 1.0e-8_wp) then
          xi = min(1.0_wp, max(-1.0_wp, r(i)))
          return
        end if
      end if
    end if
    ! Fallback: bisection on the bracket.
    lo = -1.0_wp
    hi = 1.0_wp
    fl = c - b + a
    do it = 1, 60
      xi = 0.5_wp * (lo + hi)
      fm = c + xi * (b + xi * a)
      if ((fm <= 0.0_wp) .eqv. (fl <= 0.0_wp)) then
        lo = xi
        fl = fm
      else
        hi = xi
      end if
    end do
  end function project_on_segment

  !> Outward normal (dy, -dx)/len of the edge xa -> xb (body on the left).
  pure function edge_normal(xa, xb) result(n)
    real(wp), intent(in) :: xa(2), xb(2)
    real(wp) :: n(2)
    n = [xb(2) - xa(2), xa(1) - xb(1)]
    n = n / norm2(n)
  end function edge_normal

  !> The 2D cross product a x b = a1 b2 - a2 b1.
  pure real(wp) function cross(a, b)
    real(wp), intent(in) :: a(2), b(2)
    cross = a(1) * b(2) - a(2) * b(1)
  end function cross

end module mortar_chains
