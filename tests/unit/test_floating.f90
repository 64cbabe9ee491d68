!> Bodies held only by contact (doc/method.md, "Bodies held only by contact"), unit level:
!! (a) the rigid kernel a body's supports leave free: its dimension, its span against the
!!     rigid motions written out by hand, its names, |K R| at rounding level, and fixing
!!     DOFs that make the kernel's restriction nonsingular and keep off the contact;
!! (b) the generalized inverse K^+ (the factor of K with the fixing DOFs removed, zero
!!     there): K K^+ K = K on random vectors;
!! (c) SMALBE (bound and equality constrained QPs) against the solution found by
!!     enumerating active sets and solving each KKT system, and against QPs built with a
!!     known solution;
!! (d) nnls, both methods (active set, interior point), against a brute-force search over
!!     column subsets, and on stacks of blocks (a row per block, a column per contact force)
!!     whose answer is known: balanced, pulled apart (residual: the pull), squeezed (forces
!!     that balance each other, so x is unbounded along them), in scaled and SI magnitudes.
!! Products with K are element loops (assembly's residual_full), not the assembled matrix.
program test_floating
  use kinds, only: wp
  use config, only: body_cfg_t, traction_cfg_t, boundary_cfg_t, ELEM_Q1, ELEM_P1, &
                    SIDE_LEFT, SIDE_RIGHT, SIDE_BOTTOM, BC_FREE, BC_CLAMPED, BC_ROLLER
  use mesh, only: mesh_t, group_index, group_nodes
  use gmsh_msh, only: msh_read
  use errors, only: error_t
  use assembly, only: body_system_t, assemble_body, residual_full, rigid_motion_name
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_AMD
  use linop, only: dense_op_t, dense_op_init
  use mprgp, only: mprgp_t, MPRGP_CONVERGED
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use nonneg_lsq, only: nnls, sparse_cols_t, NNLS_ACTIVE_SET, NNLS_INTERIOR
  use lapack, only: dgesv, dsyev
  use testing, only: grid_mesh_parts, report, report_le, test_summary, set_seed, error_parts, spd_from_eigs
  use errors, only: error_t
  implicit none (type, external)

  integer, parameter :: TY = 1, TX = 2, ROT = 3   ! kinds of expected rigid motions
  integer :: i

  call set_seed(12345)

  ! (a), (b) kernels of structured rectangles (0,2)x(0,1) and the force-controlled Hertz disc
  call kernel_case('no support', ELEM_Q1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], '', [.false., .false.], &
                   [TX, TY, ROT], 3, 'bottom', .true.)
  call kernel_case('no support, P1', ELEM_P1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], '', [.false., .false.], &
                   [TX, TY, ROT], 3, 'bottom', .true.)
  call kernel_case('rollers on both vertical sides', ELEM_Q1, [BC_ROLLER, BC_ROLLER, BC_FREE, BC_FREE], '', &
                   [.false., .false.], [TY, 0, 0], 1, 'bottom', .true.)
  call kernel_case('ux=0 on a horizontal line', ELEM_Q1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], 'bottom', &
                   [.true., .false.], [TY, ROT, 0], 2, 'top', .true.)
  call kernel_case('ux=0 on a vertical line', ELEM_Q1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], 'left', &
                   [.true., .false.], [TY, 0, 0], 1, 'bottom', .false.)
  call kernel_case('uy=0 on a horizontal line', ELEM_P1, [BC_FREE, BC_FREE, BC_FREE, BC_FREE], 'top', &
                   [.false., .true.], [TX, 0, 0], 1, 'bottom', .false.)
  call kernel_case('clamped', ELEM_Q1, [BC_CLAMPED, BC_FREE, BC_FREE, BC_FREE], '', [.false., .false.], &
                   [0, 0, 0], 0, 'bottom', .false.)
  call disc_case()

  ! (c) SMALBE
  do i = 1, 4
    call smalbe_known(m=3 + i, r=1 + mod(i, 2), nact=0, lower=0.0_wp, tag='no active bound')
  end do
  do i = 1, 6
    call smalbe_known(m=3 + mod(i, 6), r=1 + mod(i, 2), nact=1 + mod(i, 3), lower=merge(0.0_wp, -0.5_wp, i <= 3), &
                      tag='known active set')
  end do
  do i = 1, 8
    call smalbe_random(m=4 + mod(i, 5), r=1 + mod(i, 2), case_no=i)
  end do

  ! (d) nnls
  do i = 1, 6
    call nnls_case(r=1 + mod(i, 3), m=2 + mod(i, 5), feasible=.true., case_no=i)
    call nnls_case(r=1 + mod(i, 3), m=2 + mod(i, 5), feasible=.false., case_no=i)
  end do
  call nnls_stack(40, 1.0_wp, 1.0_wp, .false.)
  call nnls_stack(40, -1.0_wp, 1.0_wp, .false.)
  call nnls_stack(40, 1.0_wp, 1.0_wp, .true.)
  call nnls_stack(40, -1.0_wp, 1.0_wp, .true.)
  call nnls_stack(300, 1.0_wp, 2.1e11_wp, .true.)
  call nnls_stack(300, -1.0_wp, 2.1e11_wp, .false.)
  call nnls_stack(300, 1.0_wp, 1.0e-3_wp, .false.)
  call nnls_tilt(0.499999_wp)
  call nnls_tilt(0.500001_wp)

  call test_summary()

contains

  ! ---------------------------------------------------------------------------------------
  !> Uniform random numbers in [a, b).
  subroutine uniform(x, a, b)
    real(wp), intent(out) :: x(..)
    real(wp), intent(in) :: a, b
    select rank (x)
    rank (1)
      call random_number(x)
      x = a + (b - a)*x
    rank (2)
      call random_number(x)
      x = a + (b - a)*x
    end select
  end subroutine uniform

  !> The rigid motion of kind k at the nodes (ux, uy interleaved): TX (1,0), TY (0,1),
  !! ROT the rotation about p, (-(y - py), x - px).
  subroutine rigid_field(msh, k, p, v)
    type(mesh_t), intent(in) :: msh
    integer, intent(in) :: k
    real(wp), intent(in) :: p(2)
    real(wp), intent(out) :: v(:)
    integer :: n
    do n = 1, msh%nnode
      select case (k)
      case (TX)
        v(2*n - 1:2*n) = [1.0_wp, 0.0_wp]
      case (TY)
        v(2*n - 1:2*n) = [0.0_wp, 1.0_wp]
      case default
        v(2*n - 1:2*n) = [-(msh%xy(2, n) - p(2)), msh%xy(1, n) - p(1)]
      end select
    end do
  end subroutine rigid_field

  !> Distance of v from the span of the columns of q (q orthonormalised here), relative to |v|.
  real(wp) function off_span(q, v) result(d)
    real(wp), intent(in) :: q(:, :), v(:)
    real(wp), allocatable :: o(:, :), w(:)
    integer :: j, k
    allocate (o, source=q)
    allocate (w, source=v)
    do j = 1, size(o, 2)   ! modified Gram-Schmidt, twice
      do k = 1, j - 1
        o(:, j) = o(:, j) - dot_product(o(:, k), o(:, j))*o(:, k)
        o(:, j) = o(:, j) - dot_product(o(:, k), o(:, j))*o(:, k)
      end do
      o(:, j) = o(:, j)/norm2(o(:, j))
    end do
    do k = 1, size(o, 2)
      w = w - dot_product(o(:, k), w)*o(:, k)
    end do
    d = norm2(w)/norm2(v)
  end function off_span

  !> K x over the DOFs that are not prescribed (live: free and fixing), zero elsewhere.
  subroutine kmul(msh, body, live, x, y)
    type(mesh_t), intent(in) :: msh
    type(body_cfg_t), intent(in) :: body
    logical, intent(in) :: live(:)
    real(wp), intent(in) :: x(:)
    real(wp), intent(out) :: y(:)
    real(wp), allocatable :: xf(:), zero(:)
    allocate (xf(size(x)), zero(size(x)))
    zero = 0.0_wp
    xf = merge(x, 0.0_wp, live)
    call residual_full(msh, body, .true., xf, zero, y)
    where (.not. live) y = 0.0_wp
  end subroutine kmul

  !> Checks (a) and (b) on one assembled body; expect(1:nexp) the kinds of the rigid
  !! motions that must span the kernel (rotations about rot_at).
  subroutine check_body(tag, msh, body, system, expect, nexp, rot_at, contact, check_inverse)
    character(len=*), intent(in) :: tag
    type(mesh_t), intent(in) :: msh
    type(body_cfg_t), intent(in) :: body
    type(body_system_t), intent(in) :: system
    integer, intent(in) :: expect(:), nexp
    real(wp), intent(in) :: rot_at(2)
    character(len=*), intent(in) :: contact
    logical, intent(in) :: check_inverse
    real(wp), allocatable :: v(:), kr(:), x(:), y(:), z(:), w(:), zf(:)
    logical, allocatable :: live(:), pres(:)
    logical :: names_ok
    real(wp) :: worst, sub(3, 3), ev(3), work(64), err, py, px
    integer :: k, j, g, info, it
    type(error_t) :: status
    integer, allocatable :: nodes(:)
    character(len=:), allocatable :: nm
    character(len=256) :: msg
    type(chol_t) :: ch

    call report(system%nrig == nexp, tag//': kernel dimension', real(system%nrig, wp), real(nexp, wp))
    if (system%nrig /= nexp) return
    if (nexp == 0) then
      names_ok = .true.   ! (no short-circuit .or. in Fortran)
      if (allocated(system%fixing)) names_ok = size(system%fixing) == 0
      call report(names_ok, tag//': no fixing DOFs')
      return
    end if
    allocate (v(system%ndof), kr(system%ndof), live(system%ndof), pres(system%ndof))
    live = system%free_of > 0
    live(system%fixing) = .true.
    pres = .not. live
    ! span: every expected motion lies in span(R), and R has full column rank (dimension equal)
    worst = 0.0_wp
    do k = 1, nexp
      call rigid_field(msh, expect(k), rot_at, v)
      worst = max(worst, off_span(system%rig, v))
    end do
    call report_le(worst, 1.0e-12_wp, tag//': expected rigid motions lie in span(R)')
    sub(1:nexp, 1:nexp) = matmul(transpose(system%rig), system%rig)
    call dsyev('N', 'U', nexp, sub, 3, ev, work, size(work), info)
    call report(info == 0 .and. ev(1) > 1.0e-8_wp*ev(nexp), tag//': R has full column rank', ev(1)/ev(nexp))
    call report_le(max(0.0_wp, maxval(abs(system%rig), mask=spread(pres, 2, nexp))), 0.0_wp, tag//': R is 0 at prescribed DOFs')
    ! |K R| (element loop) over the live DOFs
    worst = 0.0_wp
    do j = 1, nexp
      call kmul(msh, body, live, system%rig(:, j), kr)
      worst = max(worst, maxval(abs(kr))/(system%k_norm*maxval(abs(system%rig(:, j)))))
    end do
    call report_le(worst, 1.0e-12_wp, tag//': |K R|/(|K| |R|)')
    ! names: translations along the expected axis, rotations about a point that the
    ! expected rotation's centre shares (on the line ux=0: same y; a free body: anything)
    names_ok = .true.
    do j = 1, nexp
      nm = rigid_motion_name(system, system%rig_coef(:, j))
      if (nm(1:min(len(nm), 16)) == 'rotation about (') then
        names_ok = names_ok .and. any(expect(1:nexp) == ROT)
        if (any(expect(1:nexp) == ROT) .and. nexp == 2) then
          read (nm(17:len(nm) - 1), *, iostat=info) px, py
          names_ok = names_ok .and. info == 0 .and. abs(py - rot_at(2)) <= 1.0e-6_wp
        end if
      else if (nm == 'translation along y') then
        names_ok = names_ok .and. (any(expect(1:nexp) == TY) .or. nexp == 3)
      else if (nm == 'translation along x') then
        names_ok = names_ok .and. (any(expect(1:nexp) == TX) .or. nexp == 3)
      else
        names_ok = names_ok .and. nexp == 3
      end if
      if (.not. names_ok) write (*, '(a)') '      name of motion: '//nm
    end do
    call report(names_ok, tag//': rigid motion names ('//rigid_motion_name(system, system%rig_coef(:, 1))//', ...)')
    ! fixing DOFs: as many as motions, the kernel nonsingular on them, off the contact
    call report(size(system%fixing) == nexp, tag//': one fixing DOF per free motion')
    sub = 0.0_wp
    sub(1:nexp, 1:nexp) = system%rig(system%fixing, :)
    sub(1:nexp, 1:nexp) = matmul(transpose(sub(1:nexp, 1:nexp)), sub(1:nexp, 1:nexp))
    call dsyev('N', 'U', nexp, sub, 3, ev, work, size(work), info)
    call report(info == 0 .and. ev(1) > 1.0e-6_wp*maxval(abs(system%rig))**2, &
                tag//': R restricted to the fixing DOFs is nonsingular', ev(1))
    if (len(contact) > 0) then
      g = group_index(msh, contact)
      call group_nodes(msh, g, nodes)
      call report(g > 0 .and. .not. any([(any(nodes == (system%fixing(k) + 1)/2), k=1, nexp)]), &
                  tag//': no fixing DOF on the contact group '''//contact//'''')
    end if
    if (.not. check_inverse) return
    ! (b) K K^+ K = K on random vectors: K^+ y solves the reduced system, 0 at the fixing DOFs
    call ch%factor(system%n, system%colptr, system%rowind, system%val, FACT_CHOLMOD, ORD_AMD, status)
    call error_parts(status, info, msg)
    call report(info == 0, tag//': factor with the fixing DOFs removed is positive definite')
    if (info /= 0) return
    allocate (x(system%ndof), y(system%ndof), z(system%ndof), w(system%ndof), zf(system%n))
    err = 0.0_wp
    do it = 1, 3
      call uniform(x, -1.0_wp, 1.0_wp)
      x = merge(x, 0.0_wp, live)
      call kmul(msh, body, live, x, y)
      zf = y(system%dof_of)
      call ch%solve(zf, status)
      call error_parts(status, info, msg)
      z = 0.0_wp
      z(system%dof_of) = zf
      call kmul(msh, body, live, z, w)
      err = max(err, norm2(w - y)/norm2(y))
    end do
    call ch%free()
    call report_le(err, 1.0e-10_wp, tag//': K K^+ K x = K x (3 random x, relative)')
  end subroutine check_body

  subroutine kernel_case(tag, element, bc, group, fix, expect, nexp, contact, check_inverse)
    character(len=*), intent(in) :: tag, group, contact
    integer, intent(in) :: element, bc(4), expect(3), nexp
    logical, intent(in) :: fix(2), check_inverse
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: notr(1)
    type(boundary_cfg_t), allocatable :: bnd(:)
    type(mesh_t) :: msh
    type(body_system_t) :: system
    integer :: info
    type(error_t) :: err
    character(len=256) :: msg
    real(wp) :: rot_at(2)
    body%id = 1
    body%x0 = 0.0_wp
    body%y0 = 0.0_wp
    body%width = 2.0_wp
    body%height = 1.0_wp
    body%nx = 8
    body%ny = 4
    body%element = element
    body%young = 1000.0_wp
    body%poisson = 0.3_wp
    body%bc(1:4) = bc
    allocate (bnd(merge(1, 0, len(group) > 0)))
    rot_at = [0.7_wp, 0.4_wp]
    if (len(group) > 0) then
      bnd(1)%body = 1
      bnd(1)%group = group
      bnd(1)%fix(1:2) = fix
      bnd(1)%u = 0.0_wp
      bnd(1)%origin = 'test'
      if (group == 'bottom') rot_at = [0.7_wp, 0.0_wp]   ! ux = 0 on y = 0: rotations about points of it
    end if
    call grid_mesh_parts(msh, body, info, msg)
    if (info == 0) then
      call assemble_body(msh, body, .true., notr, 0, system, err, boundaries=bnd, contact_groups=[contact])
      call error_parts(err, info, msg)
    end if
    call report(info == 0, tag//': assembled ('//trim(msg)//')')
    if (info /= 0) return
    call check_body(tag, msh, body, system, expect, nexp, rot_at, contact, check_inverse)
  end subroutine kernel_case

  !> The force-controlled Hertz disc (inputs/hertz_force.nml, h = 0.02): ux = 0 on its
  !! axis leaves the vertical translation only.
  subroutine disc_case()
    type(body_cfg_t) :: body
    type(traction_cfg_t) :: notr(1)
    type(boundary_cfg_t) :: bnd(1)
    type(mesh_t) :: msh
    type(body_system_t) :: system
    type(error_t) :: err
    integer :: info
    character(len=256) :: msg
    body%id = 1
    body%young = 1000.0_wp
    body%poisson = 0.3_wp
    body%bc = BC_FREE
    bnd(1)%body = 1
    bnd(1)%group = 'disc_axis'
    bnd(1)%fix(1:2) = [.true., .false.]
    bnd(1)%origin = 'test'
    call msh_read('inputs/gmsh/hertz_force_h0.02.msh', 'disc', 1, msh, err)
    call error_parts(err, info, msg)
    if (info == 0) then
      call assemble_body(msh, body, .true., notr, 0, system, err, boundaries=bnd, contact_groups=['disc_arc'])
      call error_parts(err, info, msg)
    end if
    call report(info == 0, 'Hertz disc, ux=0 on its axis: assembled ('//trim(msg)//')')
    if (info /= 0) return
    call check_body('Hertz disc, ux=0 on its axis', msh, body, system, [TY], 1, [0.0_wp, 0.0_wp], 'disc_arc', .true.)
  end subroutine disc_case

  ! ---------------------------------------------------------------------------------------
  !> A random SPD matrix with eigenvalues in [1, kappa] (1 among them), by testing's
  !! spd_from_eigs.
  subroutine random_spd(h, kappa)
    real(wp), intent(out) :: h(:, :)
    real(wp), intent(in) :: kappa
    real(wp), allocatable :: d(:)
    allocate (d(size(h, 1)))
    call uniform(d, 1.0_wp, kappa)
    d(1) = 1.0_wp
    call spd_from_eigs(size(h, 1), d, h)
  end subroutine random_spd

  !> The QP min 1/2 x'Hx - c'x, x >= l, Gx = e by enumerating the free sets F: solve
  !! [H_FF G_F'; G_F 0] [x_F; mu] = [c_F - H_FA l_A; e - G_A l_A] and keep the solution with
  !! x_F >= l_F and (Hx - c + G'mu)_A >= 0. nsol: how many free sets passed, nbad: how many
  !! of those gave a different x (H SPD: the minimiser is unique).
  subroutine qp_enumerate(h, c, gm, e, l, x, mu, nsol, nbad)
    real(wp), intent(in) :: h(:, :), c(:), gm(:, :), e(:), l(:)
    real(wp), intent(out) :: x(:), mu(:)
    integer, intent(out) :: nsol, nbad
    real(wp), allocatable :: kkt(:, :), rhs(:), xt(:), gr(:)
    integer, allocatable :: fr(:), ipiv(:)
    logical :: free(size(c))
    integer :: n, r, mask, nf, j, info
    real(wp) :: tol
    n = size(c)
    r = size(e)
    nsol = 0
    nbad = 0
    tol = 1.0e-11_wp*(maxval(abs(c)) + maxval(abs(e)) + maxval(abs(h)))
    allocate (xt(n), gr(n))
    do mask = 0, 2**n - 1
      free = [(btest(mask, j - 1), j=1, n)]
      fr = pack([(j, j=1, n)], free)
      nf = size(fr)
      if (nf < r) cycle   ! G_F cannot have full row rank
      allocate (kkt(nf + r, nf + r), rhs(nf + r), ipiv(nf + r))
      kkt = 0.0_wp
      kkt(1:nf, 1:nf) = h(fr, fr)
      kkt(1:nf, nf + 1:) = transpose(gm(:, fr))
      kkt(nf + 1:, 1:nf) = gm(:, fr)
      xt = l
      rhs(1:nf) = c(fr) - matmul(h(fr, :), merge(0.0_wp, l, free))
      rhs(nf + 1:) = e - matmul(gm, merge(0.0_wp, l, free))
      call dgesv(nf + r, 1, kkt, nf + r, ipiv, rhs, nf + r, info)
      if (info == 0) then
        xt(fr) = rhs(1:nf)
        gr = matmul(h, xt) - c + matmul(rhs(nf + 1:), gm)
        if (all(xt(fr) >= l(fr) - tol) .and. all(gr >= -tol .or. free)) then
          if (nsol == 0) then
            x = xt
            mu = rhs(nf + 1:)
          else if (norm2(xt - x) > 1.0e-9_wp*norm2(x)) then
            nbad = nbad + 1
          end if
          nsol = nsol + 1
        end if
      end if
      deallocate (kkt, rhs, ipiv)
    end do
  end subroutine qp_enumerate

  !> SMALBE as the contact solver sets it up (equality_rows: equality_init and equality_add_penalty): rho = 10
  !! lambda_max(H)/lambda_max(GG'), A = H + rho G'G, M0 = lambda_max/sqrt(|GG'|).
  subroutine run_smalbe(h, c, gm, e, l, x, mu, g, st, rho)
    real(wp), intent(in) :: h(:, :), c(:), gm(:, :), e(:), l(:)
    real(wp), intent(out) :: x(:), mu(:), g(:)
    type(smalbe_stats_t), intent(out) :: st
    real(wp), intent(out) :: rho
    type(dense_op_t) :: op
    type(mprgp_t) :: solver
    real(wp), allocatable :: gg(:, :)
    real(wp) :: ev(8), work(64), lmax
    integer :: r, info
    r = size(e)
    allocate (gg(r, r))
    gg = matmul(gm, transpose(gm))
    call dsyev('N', 'U', r, gg, r, ev, work, size(work), info)
    lmax = maxval(sum(abs(h), dim=1))
    rho = 10.0_wp*lmax/ev(r)
    call dense_op_init(op, h + rho*matmul(transpose(gm), gm))
    solver%opts%rtol = 1.0e-14_wp
    solver%opts%lambda_max = lmax + rho*ev(r)
    solver%opts%eq_m = lmax/sqrt(ev(r))           ! SMALBE's initial M
    ! |Gx - e| that counts as feasible: 1e-14 of |e| or of |G| |x|, whichever is larger (a
    ! small e from terms of G x that cancel is not known better than the terms' rounding)
    solver%opts%eq_feas = 1.0e-14_wp*norm2(e)
    solver%opts%eq_feas_x = 1.0e-14_wp*sqrt(ev(r))
    x = max(l, 0.0_wp)
    mu = 0.0_wp
    call smalbe_solve(solver, op, c, gm, e, rho, l, x, mu, st)
    g = solver%g
  end subroutine run_smalbe

  !> A QP with a known solution: x* with nact entries at the bound l, the rest above it;
  !! multipliers mu*; gradient g* > 0 on the active entries: c = H x* + G'mu* - g*, e = G x*.
  subroutine smalbe_known(m, r, nact, lower, tag)
    integer, intent(in) :: m, r, nact
    real(wp), intent(in) :: lower
    character(len=*), intent(in) :: tag
    real(wp) :: h(m, m), gm(r, m), c(m), e(r), l(m), xs(m), mus(r), gs(m), xe(m), mue(r)
    integer :: nsol, nbad
    character(len=64) :: lab
    call random_spd(h, 50.0_wp)
    call uniform(gm, 0.2_wp, 1.0_wp)   ! positive rows: like a contact's G, so x >= l, Gx = e is a pinch
    call uniform(xs, 0.1_wp, 2.0_wp)
    call uniform(mus, -1.0_wp, 1.0_wp)
    gs = 0.0_wp
    l = lower
    xs = xs + lower
    if (nact > 0) then
      xs(m - nact + 1:) = l(m - nact + 1:)
      call uniform(gs(m - nact + 1:), 0.1_wp, 1.0_wp)
    end if
    c = matmul(h, xs) + matmul(mus, gm) - gs
    e = matmul(gm, xs)
    write (lab, '(a,i0,a,i0,a,i0,a)') ' (m=', m, ', r=', r, ', active ', nact, ')'
    call qp_enumerate(h, c, gm, e, l, xe, mue, nsol, nbad)
    call report(nsol >= 1 .and. nbad == 0 .and. norm2(xe - xs) <= 1.0e-10_wp*norm2(xs), &
                'enumeration finds the known solution, '//tag//trim(lab))
    call check_smalbe(h, c, gm, e, l, xs, mus, tag//trim(lab))
  end subroutine smalbe_known

  !> A random QP with a feasible set: e = G x0 for a random x0 >= 0 with some zeros; the
  !! reference is the enumeration.
  subroutine smalbe_random(m, r, case_no)
    integer, intent(in) :: m, r, case_no
    real(wp) :: h(m, m), gm(r, m), c(m), e(r), l(m), x0(m), xe(m), mue(r)
    integer :: nsol, nbad
    character(len=64) :: lab
    call random_spd(h, 20.0_wp)
    call uniform(gm, -0.3_wp, 1.0_wp)
    call uniform(c, -1.0_wp, 1.0_wp)
    call uniform(x0, -0.5_wp, 1.0_wp)
    x0 = max(x0, 0.0_wp)
    x0(1) = 0.5_wp
    e = matmul(gm, x0)
    l = 0.0_wp
    write (lab, '(a,i0,a,i0,a,i0,a)') ' random QP ', case_no, ' (m=', m, ', r=', r, ')'
    call qp_enumerate(h, c, gm, e, l, xe, mue, nsol, nbad)
    call report(nsol >= 1 .and. nbad == 0, 'enumeration: one minimiser,'//trim(lab), real(nsol, wp))
    if (nsol < 1) return
    call check_smalbe(h, c, gm, e, l, xe, mue, trim(lab(2:)))
  end subroutine smalbe_random

  !> SMALBE against the reference solution (xr, mur). The augmented Lagrangian's
  !! multipliers contract by about 1/(1 + rho s) per update, s = lambda_min(G_F H_FF^-1 G_F')
  !! on the free set F of the solution: with rho s >= 0.05 SMALBE must converge within its
  !! updates; below, it may stop unconverged, but then it must say so. Converged, x must
  !! equal xr to 1e-10 and mu equal mur to 1e-8.
  subroutine check_smalbe(h, c, gm, e, l, xr, mur, lab)
    real(wp), intent(in) :: h(:, :), c(:), gm(:, :), e(:), l(:), xr(:), mur(:)
    character(len=*), intent(in) :: lab
    real(wp) :: x(size(c)), mu(size(e)), g(size(c)), rho, smin
    type(smalbe_stats_t) :: st
    logical :: conv
    character(len=80) :: info
    smin = dual_smin(h, gm, xr > l + 1.0e-12_wp*max(1.0_wp, maxval(abs(xr))))
    call run_smalbe(h, c, gm, e, l, x, mu, g, st, rho)
    conv = st%inner%status == MPRGP_CONVERGED
    write (info, '(a,i0,a,es9.2,a)') ' [updates ', st%updates, ', rho s = ', rho*smin, ']'
    if (rho*smin >= 0.05_wp) then
      call report(conv, 'SMALBE converged, '//lab//trim(info))
    else
      call report(conv .or. st%feas > 1.0e-14_wp*norm2(e), &
                  'SMALBE on an ill-conditioned G_F: converged, or says it did not, '//lab//trim(info))
      if (.not. conv) write (*, '(a,es10.3,a)') 'NOTE  SMALBE stopped unconverged, |Gx - e| = ', st%feas, &
        ' (slow multipliers: rho s small)'
    end if
    if (.not. conv) return
    call report_le(norm2(x - xr)/norm2(xr), 1.0e-10_wp, 'SMALBE x = x*, '//lab)
    call report_le(norm2(mu - mur)/max(norm2(mur), 1.0_wp), 1.0e-8_wp, 'SMALBE mu = mu*, '//lab)
    call report_le(norm2(matmul(gm, x) - e)/norm2(e), 1.0e-13_wp, 'SMALBE |Gx - e|/|e|, '//lab)
    call report_le(norm2(g - (matmul(h, x) - c + matmul(mu, gm)))/norm2(c), 1.0e-12_wp, &
                   'SMALBE g = Hx - c + G''mu, '//lab)
  end subroutine check_smalbe

  !> lambda_min(G_F H_FF^-1 G_F') (0 when F has fewer than r entries).
  real(wp) function dual_smin(h, gm, free) result(smin)
    real(wp), intent(in) :: h(:, :), gm(:, :)
    logical, intent(in) :: free(:)
    real(wp), allocatable :: hf(:, :), gf(:, :), sc(:, :), ev(:)
    integer, allocatable :: fr(:), ipiv(:)
    real(wp) :: work(64)
    integer :: r, nf, info
    r = size(gm, 1)
    allocate (fr(count(free)))
    fr = pack([(info, info=1, size(free))], free)
    nf = size(fr)
    smin = 0.0_wp
    if (nf < r) return
    allocate (hf(nf, nf), gf(nf, r), sc(r, r), ev(r), ipiv(nf))
    hf = h(fr, fr)
    gf = transpose(gm(:, fr))
    call dgesv(nf, r, hf, nf, ipiv, gf, nf, info)
    sc = matmul(gm(:, fr), gf)
    sc = 0.5_wp*(sc + transpose(sc))
    call dsyev('N', 'U', r, sc, r, ev, work, size(work), info)
    smin = max(ev(1), 0.0_wp)
  end function dual_smin

  ! ---------------------------------------------------------------------------------------
  !> Brute force min |G x - e| over x >= 0: by Caratheodory an optimum has a support of
  !! linearly independent columns, so try every such subset S (|S| <= r), solve the least
  !! squares problem on it (normal equations) and keep the best non-negative one.
  real(wp) function nnls_brute(gm, e) result(best)
    real(wp), intent(in) :: gm(:, :), e(:)
    real(wp), allocatable :: a(:, :), b(:), ev(:), work(:)
    integer, allocatable :: s(:), ipiv(:)
    integer :: r, m, mask, k, j, info
    real(wp) :: res
    r = size(gm, 1)
    m = size(gm, 2)
    best = norm2(e)   ! x = 0
    allocate (work(64))
    do mask = 1, 2**m - 1
      s = pack([(j, j=1, m)], [(btest(mask, j - 1), j=1, m)])
      k = size(s)
      if (k > r) cycle
      allocate (a(k, k), b(k), ipiv(k), ev(k))
      a = matmul(transpose(gm(:, s)), gm(:, s))
      call dsyev('N', 'U', k, a, k, ev, work, size(work), info)
      if (info == 0 .and. ev(1) > 1.0e-10_wp*ev(k)) then
        a = matmul(transpose(gm(:, s)), gm(:, s))
        b = matmul(e, gm(:, s))
        call dgesv(k, 1, a, k, ipiv, b, k, info)
        if (info == 0 .and. all(b >= 0.0_wp)) then
          res = norm2(matmul(gm(:, s), b) - e)
          best = min(best, res)
        end if
      end if
      deallocate (a, b, ipiv, ev)
    end do
  end function nnls_brute

  subroutine nnls_case(r, m, feasible, case_no)
    integer, intent(in) :: r, m, case_no
    logical, intent(in) :: feasible
    real(wp) :: gm(r, m), e(r), x(m), x0(m), res, best
    type(sparse_cols_t) :: gs
    character(len=80) :: lab
    character(len=14) :: mname
    integer :: meth
    call uniform(gm, -0.5_wp, 1.0_wp)
    call uniform(x0, 0.0_wp, 1.0_wp)
    if (feasible) then
      e = matmul(gm, x0)
    else   ! positive first row, e(1) < 0: no x >= 0 reaches e, the other rows can be met
      gm(1, :) = abs(gm(1, :)) + 0.1_wp
      e = matmul(gm, x0)
      e(1) = -0.3_wp
    end if
    call gs%from_dense(gm)
    best = nnls_brute(gm, e)
    do meth = NNLS_ACTIVE_SET, NNLS_INTERIOR
      mname = merge('active set    ', 'interior point', meth == NNLS_ACTIVE_SET)
      write (lab, '(a,i0,a,i0,a,i0,a,a,a)') ' (case ', case_no, ': r=', r, ', m=', m, ', ', &
        merge('feasible  ', 'infeasible', feasible), ')'
      lab = trim(mname)//trim(lab)
      call nnls(gs, e, x, res, meth)
      call report(all(x >= 0.0_wp), 'nnls: x >= 0, '//trim(lab))
      call report_le(abs(res - norm2(matmul(gm, x) - e))/norm2(e), 1.0e-13_wp, 'nnls: res = |Gx - e|, '//trim(lab))
      call report_le(abs(res - best)/norm2(e), 1.0e-10_wp, 'nnls: residual = brute-force minimum, '//trim(lab))
      if (feasible) then
        call report_le(res/norm2(e), 1.0e-10_wp, 'nnls: feasible -> residual 0, '//trim(lab))
      else
        call report(res > 1.0e-3_wp*norm2(e), 'nnls: infeasible -> residual > 0, '//trim(lab), res/norm2(e))
      end if
    end do
  end subroutine nnls_case

  !> A stack of nb blocks, each free along y only (one row), resting on a support: three
  !! contact forces (columns) between each block and the next, with weights 0.5, 1 and 0.7
  !! of scale (+ on the upper block, - on the lower), three under the last block. A load
  !! sign x 1e6 on the top block: pressed (+1) it is balanced (residual 0); pulled (-1) no
  !! compressive force balances it and the least residual is the pull itself, 1e6 (the
  !! forces all zero). squeezed: block nb/2 also touches a fixed plate above it (a column on
  !! its row only), so the plate's force and the stack's below it balance each other:
  !! x >= 0 with G x = 0 exists, and x is unbounded along it.
  subroutine nnls_stack(nb, sign, scale, squeezed)
    integer, intent(in) :: nb
    real(wp), intent(in) :: sign, scale
    logical, intent(in) :: squeezed
    type(sparse_cols_t) :: gs
    real(wp), allocatable :: e(:), x(:)
    real(wp) :: res(2), wts(3)
    integer :: k, c, meth
    character(len=100) :: lab
    wts = [0.5_wp, 1.0_wp, 0.7_wp]*scale
    call gs%init(nb)
    do k = 1, nb
      do c = 1, 3
        if (k < nb) then
          call gs%push([k, k + 1], [wts(c), -wts(c)])
        else
          call gs%push([k], [wts(c)])
        end if
      end do
    end do
    if (squeezed) call gs%push([nb/2], [-scale])
    allocate (e(nb), x(gs%ncol))
    e = 0.0_wp
    e(1) = sign*1.0e6_wp
    write (lab, '(a,i0,a,a,a,es8.1,a)') 'nnls stack of ', nb, merge(' pressed', ' pulled ', sign > 0.0_wp), &
      merge(', squeezed', '          ', squeezed), ', scale ', scale, ', '
    do meth = NNLS_ACTIVE_SET, NNLS_INTERIOR
      call nnls(gs, e, x, res(meth), meth)
      call report(all(x >= 0.0_wp), trim(lab)//merge(' active set', ' interior  ', meth == NNLS_ACTIVE_SET)//': x >= 0')
      if (sign > 0.0_wp) then
        call report_le(res(meth)/1.0e6_wp, 1.0e-10_wp, trim(lab)//merge(' active set', ' interior  ', &
                       meth == NNLS_ACTIVE_SET)//': residual 0 (balanced)')
      else
        call report_le(abs(res(meth) - 1.0e6_wp)/1.0e6_wp, 1.0e-9_wp, trim(lab)//merge(' active set', ' interior  ', &
                       meth == NNLS_ACTIVE_SET)//': residual = the pull')
      end if
    end do
  end subroutine nnls_stack

  !> A stack of 90 blocks, each with a vertical and a rotation row, standing on two
  !! contact points per interface at -+500 (the rotation row in units where the lever is
  !! 1e3: a body of mm size): a weight 1 and a moment fac x 1e3 on each block, so every
  !! interface carries its resultant at fac of the half-width from the centre. fac =
  !! 0.499999 is balanced at the very edge of the support (its least residual 0), 0.500001
  !! is not (the least residual is positive): the interior point method, whose iterates
  !! stall there with the primal residual left, must not call the first unbalanced (its
  !! answer is then the active set method's) and both methods give the same residual.
  subroutine nnls_tilt(fac)
    real(wp), intent(in) :: fac
    integer, parameter :: nb = 90
    real(wp), parameter :: lever = 1.0e3_wp
    type(sparse_cols_t) :: gs
    real(wp), allocatable :: e(:), x(:)
    real(wp) :: res(2), xs(2)
    integer :: k, c, meth
    character(len=80) :: lab
    xs = [-0.5_wp, 0.5_wp]*lever
    call gs%init(2*nb)
    do k = 1, nb
      do c = 1, 2
        if (k > 1) then
          call gs%push([2*k - 3, 2*k - 2, 2*k - 1, 2*k], [-1.0_wp, -xs(c), 1.0_wp, xs(c)])
        else
          call gs%push([2*k - 1, 2*k], [1.0_wp, xs(c)])
        end if
      end do
    end do
    allocate (e(2*nb), x(gs%ncol))
    e(1::2) = 1.0_wp
    e(2::2) = fac*lever
    do meth = NNLS_ACTIVE_SET, NNLS_INTERIOR
      call nnls(gs, e, x, res(meth), meth)
    end do
    write (lab, '(a,f9.6,a)') 'nnls tilting stack, resultant at ', fac, ' of the width'
    if (fac < 0.5_wp) then
      call report_le(maxval(res)/norm2(e), 1.0e-10_wp, trim(lab)//': both methods balance it')
    else
      call report(minval(res)/norm2(e) > 1.0e-10_wp, trim(lab)//': neither balances it', minval(res)/norm2(e))
    end if
    call report_le(abs(res(1) - res(2))/norm2(e), 1.0e-9_wp, trim(lab)//': the same residual')
  end subroutine nnls_tilt

end program test_floating
