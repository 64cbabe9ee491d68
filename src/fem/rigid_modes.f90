!> The rigid motions of one body that its prescribed displacements leave free (a body
!! held only by contact): the kernel of its stiffness, spanned by combinations of the
!! three rigid modes (1,0), (0,1) and the rotation about the body's centre, and the fixing
!! DOFs that make the factorized system nonsingular (a generalized inverse, module
!! floating's use). Fills the rigid-motion fields of body_system_t.
module rigid_modes
  use kinds, only: wp
  use space, only: NDIM, NCOMP, NRIGID, node_dof
  use config, only: body_cfg_t, BC_CONTACT
  use mesh, only: mesh_t, side_nodes, group_index, group_nodes
  use lapack, only: dgesvd
  use body_system, only: body_system_t
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  implicit none (type, external)
  private

  public :: rigid_kernel, choose_fixing, rigid_motion_name

contains

  !> The rigid motions that the prescribed DOFs leave free: the null space of the three
  !! rigid modes (1,0), (0,1), (-(y-yc), x-xc)/h restricted to the prescribed DOFs: the right
  !! singular vectors of that (prescribed DOFs x 3) matrix A with singular values below 1e-10
  !! of the largest (all three when nothing is prescribed). A is reduced to its 3 x 3
  !! triangle R by Givens rotations row by row (no Gram matrix: squaring would put a thin
  !! clamp, the short side of a 1e5:1 strip, below the rounding of a true kernel), then R's
  !! SVD. A true kernel has singular value ~ eps; a support of length l on a body of size h
  !! has ~ l/h, so the test is scale-free and holds to aspect ratios of about 1e9. Sets sys%nrig, rig_coef, rig_xc, rig_h and
  !! sys%rig (ndof x nrig, zero at prescribed DOFs).
  subroutine rigid_kernel(mesh, prescribed, sys, err, axisymmetric)
    type(mesh_t), intent(in) :: mesh           !< the body's mesh
    logical, intent(in) :: prescribed(:)       !< (ndof) whether each DOF is prescribed
    type(body_system_t), intent(inout) :: sys  !< gets nrig, rig, rig_coef, rig_xc, rig_h
    type(error_t), intent(out) :: err          !< ERR_NUMERICAL when the SVD fails
    !> a meridian section: a motion along x (r) or a rotation strains the hoop, so only the
    !! translation along the axis (y) is rigid
    logical, intent(in), optional :: axisymmetric
    real(wp) :: g(NRIGID, NRIGID), r(NRIGID), ev(NRIGID), work(64), top, vt(NRIGID, NRIGID), dummy(1, 1)
    integer :: k, cc, j, lapinfo, nk
    character(len=512) :: emsg

    sys%rig_xc = 0.0_wp
    sys%rig_xc(1:NDIM) = 0.5_wp*(maxval(mesh%xy, dim=2) + minval(mesh%xy, dim=2))
    sys%rig_h = max(maxval(maxval(mesh%xy, dim=2) - minval(mesh%xy, dim=2)), tiny(1.0_wp))
    g = 0.0_wp
    if (present(axisymmetric)) then
      if (axisymmetric) then
        call givens_add_row(g, [1.0_wp, 0.0_wp, 0.0_wp])
        call givens_add_row(g, [0.0_wp, 0.0_wp, 1.0_wp])
      end if
    end if
    do k = 1, mesh%nnode
      do cc = 1, NCOMP
        if (.not. prescribed(node_dof(k, cc))) cycle
        r = rigid_row(sys, mesh%xy(:, k), cc)
        call givens_add_row(g, r)
      end do
    end do
    call dgesvd('N', 'A', NRIGID, NRIGID, g, NRIGID, ev, dummy, 1, vt, NRIGID, work, size(work), lapinfo)
    top = max(ev(1), 0.0_wp)
    nk = 0
    if (lapinfo /= 0) then
      write (emsg, '(a,i0,a)') 'body ', sys%id, ': LAPACK dgesvd failed on the 3 x 3 triangle of its '// &
        'rigid modes (the kernel of its supports is unknown)'
      call err%set(ERR_NUMERICAL, emsg)
      return
    end if
    nk = count(ev <= 1.0e-10_wp*top)
    if (top <= 0.0_wp) nk = NRIGID
    ! the kernel, smallest singular value first (the order the Gram eigenvectors had)
    do j = 1, NRIGID
      g(:, j) = vt(NRIGID + 1 - j, :)
    end do
    sys%nrig = nk
    if (nk == 0) return
    ! ascending eigenvalues: the kernel is the first nk columns (nothing prescribed: identity)
    allocate (sys%rig_coef(NRIGID, nk), sys%rig(sys%ndof, nk))
    if (top <= 0.0_wp) then
      sys%rig_coef = 0.0_wp
      do j = 1, NRIGID
        sys%rig_coef(j, j) = 1.0_wp
      end do
    else
      sys%rig_coef = g(:, 1:nk)
      call tidy_basis(sys%rig_coef)
    end if
    do j = 1, nk
      do k = 1, mesh%nnode
        do cc = 1, NCOMP
          if (prescribed(node_dof(k, cc))) then
            sys%rig(node_dof(k, cc), j) = 0.0_wp
          else
            sys%rig(node_dof(k, cc), j) = dot_product(rigid_row(sys, mesh%xy(:, k), cc), sys%rig_coef(:, j))
          end if
        end do
      end do
    end do
  end subroutine rigid_kernel

  !> Add the row r to the upper triangle rt of a QR factorization by NRIGID Givens rotations.
  pure subroutine givens_add_row(rt, r)
    real(wp), intent(inout) :: rt(NRIGID, NRIGID)   !< upper triangular R (below the diagonal: zero)
    real(wp), intent(in) :: r(NRIGID)               !< the new row
    real(wp) :: w(NRIGID), c, s, rho
    integer :: i
    w = r
    do i = 1, NRIGID
      if (w(i) == 0.0_wp) cycle
      rho = hypot(rt(i, i), w(i))
      c = rt(i, i)/rho
      s = w(i)/rho
      rt(i, i) = rho
      w(i) = 0.0_wp
      if (i < NRIGID) then
        block
          real(wp) :: row(NRIGID - i)
          row = rt(i, i + 1:NRIGID)
          rt(i, i + 1:NRIGID) = c*row + s*w(i + 1:NRIGID)
          w(i + 1:NRIGID) = -s*row + c*w(i + 1:NRIGID)
        end block
      end if
    end do
  end subroutine givens_add_row

  !> Component cc of the NRIGID basis rigid modes at the point x: the translations, then the
  !! rotation about rig_xc scaled by rig_h.
  pure function rigid_row(sys, x, cc) result(r)
    type(body_system_t), intent(in) :: sys
    real(wp), intent(in) :: x(:)              ! (NDIM) the node
    integer, intent(in) :: cc
    real(wp) :: r(NRIGID), d(3)
    r = 0.0_wp
    r(cc) = 1.0_wp
    if (NDIM == 2) then
      if (cc == 1) r(3) = -(x(2) - sys%rig_xc(2))/sys%rig_h
      if (cc == 2) r(3) = (x(1) - sys%rig_xc(1))/sys%rig_h
    else      ! component cc of e_k x d, d = (x - xc)/h, for the rotations about x, y, z
      d = (x(1:3) - sys%rig_xc)/sys%rig_h
      select case (cc)
      case (1)
        r(5) = d(3)
        r(6) = -d(2)
      case (2)
        r(4) = -d(3)
        r(6) = d(1)
      case default
        r(4) = d(2)
        r(5) = -d(1)
      end select
    end if
  end function rigid_row

  !> Round a kernel basis to its simplest form: entries below 1e-12 become 0 and each
  !! column gets a positive largest entry (a pure translation reads (0, 1, 0)).
  pure subroutine tidy_basis(c)
    real(wp), intent(inout) :: c(:, :)
    integer :: j
    do j = 1, size(c, 2)
      if (c(maxloc(abs(c(:, j)), dim=1), j) < 0.0_wp) c(:, j) = -c(:, j)
      where (abs(c(:, j)) < 1.0e-12_wp) c(:, j) = 0.0_wp
      c(:, j) = c(:, j)/norm2(c(:, j))
    end do
  end subroutine tidy_basis

  !> The rigid motion with coefficients c (basis of rigid_kernel) in words: 'translation
  !! along x', 'translation along (0.6, 0.8)', 'rotation about (x0, y0)'.
  function rigid_motion_name(sys, c) result(s)
    type(body_system_t), intent(in) :: sys  !< the body's system (rig_xc, rig_h)
    real(wp), intent(in) :: c(NRIGID)       !< coefficients in the basis of rigid_kernel
    character(len=:), allocatable :: s
    character(len=64) :: buf
    real(wp) :: w, t(2)
    if (NDIM == 3) then
      s = solid_motion_name(sys, c)
      return
    end if
    w = c(3)/sys%rig_h
    t = c(1:2)
    if (abs(c(3)) <= 1.0e-8_wp*norm2(c)) then
      if (abs(t(2)) <= 1.0e-8_wp*norm2(t)) then
        s = 'translation along x'
      else if (abs(t(1)) <= 1.0e-8_wp*norm2(t)) then
        s = 'translation along y'
      else
        write (buf, '(a,f7.4,a,f7.4,a)') 'translation along (', t(1)/norm2(t), ', ', t(2)/norm2(t), ')'
        s = trim(buf)
      end if
    else
      ! the centre, its coordinates below 1e-9 of the body's size shown as 0
      t = [sys%rig_xc(1) - t(2)/w, sys%rig_xc(2) + t(1)/w]
      where (abs(t) < 1.0e-9_wp*sys%rig_h) t = 0.0_wp
      write (buf, '(a,g0.6,a,g0.6,a)') 'rotation about (', t(1), ', ', t(2), ')'
      s = trim(buf)
    end if
  end function rigid_motion_name

  !> A solid body's rigid motion in words: 'translation along (tx, ty, tz)' (an axis named
  !! 'x', 'y', 'z'), or 'rotation about the axis (ax, ay, az) through (px, py, pz)' (the
  !! point of the axis nearest the basis centre), a screw motion's translation along its axis
  !! added as 'with translation s along it'.
  function solid_motion_name(sys, c) result(s)
    type(body_system_t), intent(in) :: sys
    real(wp), intent(in) :: c(:)
    character(len=:), allocatable :: s
    character(len=160) :: buf
    real(wp) :: t(3), w(3), a(3), p(3), ax
    integer :: k
    t = c(1:3)
    w = c(4:6)/sys%rig_h
    if (norm2(c(4:6)) <= 1.0e-8_wp*norm2(c)) then
      t = t/norm2(t)
      k = maxloc(abs(t), dim=1)
      if (abs(abs(t(k)) - 1.0_wp) <= 1.0e-8_wp) then
        s = 'translation along '//'xyz'(k:k)
      else
        write (buf, '(a,3(f7.4,a))') 'translation along (', t(1), ', ', t(2), ', ', t(3), ')'
        s = trim(buf)
      end if
      return
    end if
    ! u(x) = t + w x (x - xc): the axis through p = xc + w x t / |w|^2, along w
    a = w/norm2(w)
    p = sys%rig_xc + [w(2)*t(3) - w(3)*t(2), w(3)*t(1) - w(1)*t(3), w(1)*t(2) - w(2)*t(1)]/dot_product(w, w)
    where (abs(p) < 1.0e-9_wp*sys%rig_h) p = 0.0_wp
    where (abs(a) < 1.0e-9_wp) a = 0.0_wp
    write (buf, '(a,3(f7.4,a),3(g0.6,a))') 'rotation about the axis (', a(1), ', ', a(2), ', ', a(3), ') through (', &
      p(1), ', ', p(2), ', ', p(3), ')'
    s = trim(buf)
    ax = dot_product(t, a)     ! a screw: the translation along the axis per unit of rotation
    if (abs(ax) > 1.0e-8_wp*max(norm2(t), tiny(1.0_wp))) then
      write (buf, '(a,g0.6,a)') ' with translation ', ax/norm2(w), ' per radian along it'
      s = s//trim(buf)
    end if
  end function solid_motion_name

  !> The fixing DOFs of a floating body: sys%nrig DOFs that are not prescribed, not on the
  !! contact (the contact group, or a rectangle's 'contact' side), on which the kernel is
  !! nonsingular, taken from two nodes far apart (the node closest to the contact off it,
  !! and the node farthest from that one) for the largest |det| of the kernel restricted to
  !! them. They are prescribed to 0 (prescribed) for the factorization only.
  subroutine choose_fixing(mesh, body, prescribed, sys, err, contact_groups)
    type(mesh_t), intent(in) :: mesh                         !< the body's mesh
    type(body_cfg_t), intent(in) :: body                     !< its id and side conditions
    logical, intent(inout) :: prescribed(:)                  !< (ndof) the fixing DOFs are added
    type(body_system_t), intent(inout) :: sys                !< gets fixing; its u_fixed is 0 there
    type(error_t), intent(out) :: err                        !< ERR_INPUT when no fixing DOFs are found
    character(len=*), intent(in), optional :: contact_groups(:)  !< the body's contact groups, kept clear
    logical, allocatable :: avoid(:)
    integer, allocatable :: nodes(:), order(:)
    integer :: side, g, k, p(2), cand(2*NCOMP), nc, i, j, l, best(3), r, c
    real(wp) :: ctr(NDIM), d, dbest, det, detbest, sub(3, 3)
    character(len=512) :: emsg

    r = sys%nrig
    allocate (avoid(mesh%nnode))
    avoid = .false.
    do side = 1, 2*NDIM
      if (body%bc(side) /= BC_CONTACT) cycle
      call side_nodes(mesh, side, nodes)
      avoid(nodes) = .true.
    end do
    if (present(contact_groups)) then
      do k = 1, size(contact_groups)
        g = 0
        if (len_trim(contact_groups(k)) > 0) g = group_index(mesh, contact_groups(k))
        if (g > 0) then
          call group_nodes(mesh, g, nodes)
          avoid(nodes) = .true.
        end if
      end do
    end if
    ! the first node: the closest to the contact's centroid off the contact (the centre when
    ! there is none), so that K^+'s contact displacements are measured from a near point and
    ! stay small (the rigid part R alpha then does not cancel a large pinned deformation)
    ! the nodes in the file's order (a mesh from a file is numbered otherwise), so that the
    ! choice among nodes at the same distance does not depend on the numbering
    order = [(k, k=1, mesh%nnode)]
    if (allocated(mesh%file_node)) order(mesh%file_node) = [(k, k=1, mesh%nnode)]
    ctr = sys%rig_xc(1:NDIM)
    do c = 1, NDIM
      if (any(avoid) .and. allocated(mesh%file_node)) then
        ctr(c) = sum(mesh%xy(c, order), mask=avoid(order))/count(avoid)
      else if (any(avoid)) then
        ctr(c) = sum(mesh%xy(c, :), mask=avoid)/count(avoid)
      end if
    end do
    p = 0
    dbest = huge(1.0_wp)
    do i = 1, mesh%nnode
      k = order(i)
      if (avoid(k) .or. all(prescribed(node_dof(k, 1):node_dof(k, NCOMP)))) cycle
      d = norm2(mesh%xy(:, k) - ctr)
      if (d < dbest) then
        dbest = d
        p(1) = k
      end if
    end do
    if (p(1) == 0) then
      write (emsg, '(a,i0,a)') 'body ', body%id, ' is held only by contact, but every node is on the '// &
        'contact or prescribed: no node is left to fix its rigid motion for the factorization; '// &
        'refine the mesh or support the body'
      call err%set(ERR_INPUT, emsg)
      return
    end if
    dbest = -1.0_wp
    do i = 1, mesh%nnode
      k = order(i)
      if (avoid(k) .or. all(prescribed(node_dof(k, 1):node_dof(k, NCOMP)))) cycle
      d = norm2(mesh%xy(:, k) - mesh%xy(:, p(1)))
      if (d > dbest) then
        dbest = d
        p(2) = k
      end if
    end do
    if (NDIM == 3) then      ! up to six motions: a third node, and the best r of their DOFs
      call solid_fixing(avoid, order)
      return
    end if
    nc = 0
    do i = 1, 2          ! the two nodes chosen
      do j = 1, NCOMP
        k = node_dof(p(i), j)
        if (.not. prescribed(k) .and. .not. any(cand(1:nc) == k)) then
          nc = nc + 1
          cand(nc) = k
        end if
      end do
    end do
    ! the r candidates with the largest |det R(fix, :)| (at most 4 choose 3 tries)
    detbest = 0.0_wp
    best = 0
    do i = 1, nc
      do j = merge(i + 1, i, r > 1), merge(nc, i, r > 1)
        do l = merge(j + 1, j, r > 2), merge(nc, j, r > 2)
          if (r > 1 .and. j == i) cycle
          if (r > 2 .and. l == j) cycle
          sub = 0.0_wp
          sub(1, 1:r) = sys%rig(cand(i), 1:r)
          if (r > 1) sub(2, 1:r) = sys%rig(cand(j), 1:r)
          if (r > 2) sub(3, 1:r) = sys%rig(cand(l), 1:r)
          det = abs(small_det(sub, r))
          if (det > detbest) then
            detbest = det
            best = [cand(i), cand(j), cand(l)]
          end if
        end do
      end do
    end do
    if (.not. detbest > 1.0e-6_wp) then
      write (emsg, '(a,i0,a)') 'body ', body%id, ' is held only by contact, but no pair of nodes away '// &
        'from the contact fixes its free rigid motion for the factorization; support the body'
      call err%set(ERR_INPUT, emsg)
      return
    end if
    allocate (sys%fixing(r))
    sys%fixing = best(1:r)
    prescribed(sys%fixing) = .true.
    sys%u_fixed(sys%fixing) = 0.0_wp

  contains

    !> A solid body: a third node, the farthest from the line through the first two, and of
    !! the three nodes' free DOFs (at most 9) the r with the largest |det R(fix, :)| (every
    !! r-subset tried: at most 84).
    subroutine solid_fixing(avoid, order)
      logical, intent(in) :: avoid(:)
      integer, intent(in) :: order(:)
      integer :: cand3(9), pick(6), bestp(6), n3, kk
      real(wp) :: axis(3), dd, sub6(6, 6)
      axis = mesh%xy(:, p(2)) - mesh%xy(:, p(1))
      axis = axis/max(norm2(axis), tiny(1.0_wp))
      kk = 0
      dbest = -1.0_wp
      do i = 1, mesh%nnode
        k = order(i)
        if (avoid(k) .or. all(prescribed(node_dof(k, 1):node_dof(k, NCOMP)))) cycle
        dd = norm2((mesh%xy(:, k) - mesh%xy(:, p(1))) - dot_product(mesh%xy(:, k) - mesh%xy(:, p(1)), axis)*axis)
        if (dd > dbest) then
          dbest = dd
          kk = k
        end if
      end do
      n3 = 0
      do i = 1, 3
        l = merge(p(min(i, 2)), kk, i < 3)
        if (l == 0) cycle
        do j = 1, NCOMP
          k = node_dof(l, j)
          if (.not. prescribed(k) .and. .not. any(cand3(1:n3) == k)) then
            n3 = n3 + 1
            cand3(n3) = k
          end if
        end do
      end do
      detbest = 0.0_wp
      bestp = 0
      pick(1:r) = [(j, j=1, r)]
      if (n3 >= r) then
        do
          do i = 1, r
            sub6(i, 1:r) = sys%rig(cand3(pick(i)), 1:r)
          end do
          det = abs(lu_det(sub6(1:r, 1:r)))
          if (det > detbest) then
            detbest = det
            bestp(1:r) = cand3(pick(1:r))
          end if
          ! the next r-subset of 1..n3 in lexicographic order
          i = r
          do while (i >= 1)
            if (pick(i) < n3 - r + i) exit
            i = i - 1
          end do
          if (i < 1) exit
          pick(i) = pick(i) + 1
          pick(i + 1:r) = [(pick(i) + j, j=1, r - i)]
        end do
      end if
      if (.not. detbest > 1.0e-6_wp) then
        write (emsg, '(a,i0,a)') 'body ', body%id, ' is held only by contact, but no three nodes away '// &
          'from the contact fix its free rigid motions for the factorization; support the body'
        call err%set(ERR_INPUT, emsg)
        return
      end if
      allocate (sys%fixing(r))
      sys%fixing = bestp(1:r)
      prescribed(sys%fixing) = .true.
      sys%u_fixed(sys%fixing) = 0.0_wp
    end subroutine solid_fixing
  end subroutine choose_fixing

  !> The determinant of a small square matrix by Gaussian elimination with partial pivoting.
  pure real(wp) function lu_det(a0) result(d)
    real(wp), intent(in) :: a0(:, :)
    real(wp) :: a(size(a0, 1), size(a0, 1)), t(size(a0, 1))
    integer :: n, k, pv, i
    a = a0
    n = size(a, 1)
    d = 1.0_wp
    do k = 1, n
      pv = k - 1 + maxloc(abs(a(k:n, k)), dim=1)
      if (a(pv, k) == 0.0_wp) then
        d = 0.0_wp
        return
      end if
      if (pv /= k) then
        t = a(k, :)
        a(k, :) = a(pv, :)
        a(pv, :) = t
        d = -d
      end if
      d = d*a(k, k)
      do i = k + 1, n
        a(i, k + 1:n) = a(i, k + 1:n) - a(i, k)/a(k, k)*a(k, k + 1:n)
      end do
    end do
  end function lu_det

  !> Determinant of the leading r x r block (r = 1..3).
  pure real(wp) function small_det(a, r) result(d)
    real(wp), intent(in) :: a(3, 3)
    integer, intent(in) :: r
    select case (r)
    case (1)
      d = a(1, 1)
    case (2)
      d = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
    case default
      d = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) + &
          a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
    end select
  end function small_det

end module rigid_modes
