!> Bodies held only by contact (doc/method.md, "Bodies held only by contact"): the equilibrium
!! rows of a floating body, G_a = R_a' B_a' and e_a = R_a' f_a (its load balanced by its
!! contact forces: G_a lam = e_a), and the checks that the contact can hold it: every
!! free rigid motion has a contact normal component (else the body slides or turns
!! freely: bad input), the load can be balanced by compressive forces lam >= 0 (else it
!! pulls the body away: bad input), and two floating bodies are not free as a pair. With
!! friction the tangential forces take their share within the friction cone (Coulomb:
!! |lam_t| <= mu lam_n, written as the two generators lam_n (1, +-mu)) or unbounded by the
!! normal force (Tresca), so a body held by friction alone passes, and one pushed beyond
!! mu times its normal load does not (it would slide: no static equilibrium).
module floating
  use kinds, only: wp
  use space, only: NDIM, NCOMP, NRIGID, node_dof, dof_node, dof_comp
  use assembly, only: body_system_t, rigid_motion_name
  use contact_interface, only: interface_t, body_slots, slot_row, slot_side, has_friction, DIR_NORMAL, row_direction
  use config, only: FRICTION_COULOMB, FRICTION_TRESCA
  use condense, only: body_condensed_t
  use contact_common, only: scatter
  use lapack, only: dsyev, dsygv, dpotrf
  use strings, only: i2s, sci
  use errors, only: error_t, ERR_INPUT, ERR_NUMERICAL
  use nonneg_lsq, only: nnls, sparse_cols_t, gram_t, NNLS_DENSE_MAX, NNLS_ACTIVE_SET, NNLS_INTERIOR
  implicit none (type, external)
  private

  public :: rigid_rows, check_held, check_pressed, free_list, fixing_list, friction_edge

  !> A body held by Coulomb friction is on the edge of sliding when its load cannot be
  !! balanced with mu lowered by this fraction
  real(wp), parameter :: EDGE_MARGIN = 1.0e-6_wp
  !> the sides of the polygon that stands for a node's friction disc in space (cone_columns)
  integer, parameter :: CONE_SIDES = 64
  real(wp), parameter :: PI = 3.141592653589793238_wp

  !> a free motion counts as held by the contact when at least this fraction of its reach on the
  !! contact (squared) is normal to it (1%: mu >= 1e-4)
  real(wp), parameter :: HOLD_MIN = 1.0e-4_wp

contains

  !> cbody%rg = R_a' B_a' (row k: B_a applied to kernel vector k, from the interface's rows
  !! over global DOFs; B_a never touches a fixing DOF) and cbody%re = R_a' f_a (the applied
  !! load along each free motion: the lifting of prescribed displacements has no part
  !! along R_a, since K R_a = 0). Needs no factorization: the checks run before it.
  subroutine rigid_rows(contact_line, a, system, cbody)
    type(interface_t), intent(in) :: contact_line   !< contact rows of all pairs
    integer, intent(in) :: a                        !< the body
    type(body_system_t), intent(in) :: system       !< its system
    type(body_condensed_t), intent(inout) :: cbody  !< receives slots, nrig, rg, re, rreach
    integer :: k, i, e, row, side, m
    integer :: l, nd, c
    real(wp) :: dotkl
    cbody%slots = body_slots(contact_line, a)
    m = size(cbody%slots)
    cbody%m = m
    cbody%nrig = system%nrig
    if (allocated(cbody%rg)) deallocate (cbody%rg, cbody%re)
    if (allocated(cbody%rreach)) deallocate (cbody%rreach)
    allocate (cbody%rg(system%nrig, m), cbody%re(system%nrig), cbody%rreach(system%nrig, system%nrig))
    cbody%rreach = 0.0_wp
    do k = 1, system%nrig
      do i = 1, m
        row = slot_row(cbody%slots(i), contact_line%m)
        side = slot_side(cbody%slots(i), contact_line%m)
        cbody%rg(k, i) = 0.0_wp
        associate (b => contact_line%b(side))
          do e = b%ptr(row), b%ptr(row + 1) - 1
            cbody%rg(k, i) = cbody%rg(k, i) + b%val(e)*system%rig(b%dof(e), k)
            ! the motions' vectors at the entry's node, against the coefficient's weight
            nd = dof_node(b%dof(e))
            do l = 1, system%nrig
              dotkl = 0.0_wp
              do c = 1, NCOMP
                dotkl = dotkl + system%rig(node_dof(nd, c), k)*system%rig(node_dof(nd, c), l)
              end do
              cbody%rreach(k, l) = cbody%rreach(k, l) + b%val(e)**2*dotkl
            end do
          end do
        end associate
      end do
      cbody%re(k) = dot_product(system%rig(:, k), system%f_applied)
    end do
    ! a load with no part along the free motions (to rounding) has none: e = 0 exactly, the
    ! sign that only a deformation can press the body into the contact (check_pressed)
    if (.not. norm2(cbody%re) > 1.0e-12_wp*max(sum(abs(system%f_applied)), tiny(1.0_wp))) cbody%re = 0.0_wp
  end subroutine rigid_rows

  !> Can the contact hold the floating bodies? err = ERR_INPUT with the sentence when a
  !! free motion has no contact normal component, when the load cannot be balanced by
  !! compressive contact forces, when nothing presses the body into the contact, or when
  !! floating bodies in contact with each other are free together (a sub-assembly).
  subroutine check_held(contact_line, systems, bodies, err)
    type(interface_t), intent(in) :: contact_line
    type(body_system_t), intent(in) :: systems(:)
    type(body_condensed_t), intent(in) :: bodies(:)
    type(error_t), intent(out) :: err
    character(len=:), allocatable :: msg
    real(wp), allocatable :: gg(:, :), ev(:)
    real(wp) :: cm(NRIGID), f(NCOMP), sl(NDIM), along, res, enorm
    integer :: a, r, m, lapinfo, i, k
    type(sparse_cols_t) :: gsp
    character(len=:), allocatable :: hold

    hold = 'hold that rigid motion with a support: a ''clamped'' side, a ''roller'', or ux/uy'// &
           trim(merge('/uz', '   ', NDIM == 3))//' on a group (&boundary)'

    do a = 1, size(bodies)
      r = bodies(a)%nrig
      if (r == 0) cycle
      m = bodies(a)%m
      do k = 1, NCOMP                     ! the load's resultant
        f(k) = sum(systems(a)%f_applied(k::NCOMP))
      end do
      ! 1. every free motion must meet the contact normals: min over motions v of
      ! |G'v|^2 / (v'S v), the part of the motion's reach on the contact that is normal to it
      ! (generalized eigenproblem G G' v = theta S v), at least HOLD_MIN. A disc on a flat
      ! surface turning about its centre has normals through the centre: theta is only the
      ! discretisation's error of the normals (1e-6), not a hold
      allocate (gg(r, r), ev(r))
      gg = matmul(bodies(a)%rg, transpose(bodies(a)%rg))
      call held_motions(gg, bodies(a)%rreach, r, ev, lapinfo)
      if (lapinfo == 0 .and. ev(1) <= HOLD_MIN) then
        cm = matmul(systems(a)%rig_coef, gg(:, 1))
        along = dot_product(gg(:, 1), bodies(a)%re)
        msg = 'body '//i2s(a)//' is held only by contact (its supports leave rigid motion free), '// &
              'but the contact cannot hold its '//rigid_motion_name(systems(a), cm)//': the contact normals '// &
              'have (almost) no component along it (frictionless contact lets the body slide or turn)'
        if (abs(along) > 1.0e-10_wp*max(norm2(f), tiny(1.0_wp))) msg = msg// &
          '; its load has a component '//sci(along)//' along that motion, which no contact force balances'
        call err%set(ERR_INPUT, msg//'; '//hold)
        return
      end if
      deallocate (gg, ev)
      ! 2. something must press it into the contact: a load along its free motions, or (e = 0,
      ! decided after condensation by check_pressed) a deformation, by loads or prescribed
      ! displacements, that no rigid motion of the body can undo
      enorm = norm2(bodies(a)%re)
      if (enorm == 0.0_wp .and. m > 0) cycle
      if (m == 0) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//' is held only by contact (free: '//free_list(systems(a))//'), but no load '// &
              'presses it into the contact (load resultant '//vec_text(f)//'): its position '// &
              'is undetermined; load it towards the body it touches, or '//hold)
        return
      end if
      ! 3. the load must be balanced by compressive contact forces: lam >= 0, G lam = e
      ! (with friction: within the friction limits, Tresca's bound included)
      call gsp%from_dense(bodies(a)%rg)
      call admissible_nnls(contact_line, slot_row(bodies(a)%slots, contact_line%m), gsp, bodies(a)%re, res)
      if (res > 1.0e-8_wp*enorm .and. has_friction(contact_line)) then
        ! the direction it would slide in: the load's part along the contact (its
        ! resultant less its part along the mean normal of the body's contact rows)
        sl = 0.0_wp
        do i = 1, m
          if (contact_line%dir(slot_row(bodies(a)%slots(i), contact_line%m)) == DIR_NORMAL) &
            sl = sl + row_direction(contact_line, slot_row(bodies(a)%slots(i), contact_line%m))
        end do
        sl = f - dot_product(f, sl)/max(sum(sl**2), tiny(1.0_wp))*sl
        sl = sl/max(norm2(sl), tiny(1.0_wp))
        call err%set(ERR_INPUT, 'body '//i2s(a)//' is held only by contact (free: '//free_list(systems(a))//'), and its load '// &
              '(resultant '//vec_text(f)//') cannot be balanced by contact forces within the friction '// &
              'limits (|t| <= mu p, or the Tresca bound): it would slide along '//vec_text(sl)// &
              '; no static equilibrium (unbalanced part '//sci(res)//'): raise mu, lower the tangential load, or '//hold)
        return
      else if (res > 1.0e-8_wp*enorm) then
        call err%set(ERR_INPUT, 'body '//i2s(a)//' is held only by contact (free: '//free_list(systems(a))//'), but its load '// &
              '(resultant '//vec_text(f)//') pulls it away from the contact: no compressive '// &
              'contact force balances it (an unbalanced part '//sci(res)//' remains); reverse the load '// &
              'or '//hold)
        return
      end if
    end do
    ! 4. floating bodies that touch each other: each such group together must be held too
    call check_groups(contact_line, systems, bodies, err)

  contains

    !> '(vx, vy)' or '(vx, vy, vz)'.
    function vec_text(v) result(t)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: t
      integer :: j
      t = '('//sci(v(1))
      do j = 2, size(v)
        t = t//', '//sci(v(j))
      end do
      t = t//')'
    end function vec_text
  end subroutine check_held

  !> The floating bodies held by Coulomb friction at the edge of sliding: those whose load
  !! the contact balances with mu (check_held passed) but not with mu (1 - EDGE_MARGIN). Their
  !! equilibrium exists but a change of the load by a millionth would break it, and the
  !! tangential forces that hold them are barely determined. One sentence per such body in
  !! msg ('' when none).
  function friction_edge(contact_line, systems, bodies) result(msg)
    type(interface_t), intent(in) :: contact_line
    type(body_system_t), intent(in) :: systems(:)
    type(body_condensed_t), intent(in) :: bodies(:)
    character(len=:), allocatable :: msg
    type(sparse_cols_t) :: gsp, gc
    real(wp), allocatable :: lam(:)
    real(wp) :: res, enorm
    integer :: a
    msg = ''
    if (.not. any(contact_line%pair_friction == FRICTION_COULOMB)) return
    do a = 1, size(bodies)
      if (bodies(a)%nrig == 0 .or. bodies(a)%m == 0) cycle
      enorm = norm2(bodies(a)%re)
      if (enorm == 0.0_wp) cycle
      call gsp%from_dense(bodies(a)%rg)
      gc = cone_columns(contact_line, slot_row(bodies(a)%slots, contact_line%m), gsp, 1.0_wp - EDGE_MARGIN)
      allocate (lam(gc%ncol))
      call nnls(gc, bodies(a)%re, lam, res)
      deallocate (lam)
      if (res > 1.0e-8_wp*enorm) msg = msg//merge('; ', '  ', len(msg) > 0)//'body '//i2s(a)// &
        ' (free: '//free_list(systems(a))//') is held by friction at the edge of sliding: its load needs the '// &
        'full friction limit mu N (with mu 1e-6 lower it would slide), so its tangential forces are barely '// &
        'determined; lower the tangential load or raise mu for a margin'
    end do
    if (len(msg) > 0) msg = msg(3:)
  end function friction_edge

  !> The groups of floating bodies connected by pairs of two floating bodies (each alone
  !! passed check_held): their rows stacked over the union of their contact rows must have
  !! full rank (no joint free motion) and their loads must be balanced by compressive forces.
  subroutine check_groups(contact_line, systems, bodies, err)
    type(interface_t), intent(in) :: contact_line
    type(body_system_t), intent(in) :: systems(:)
    type(body_condensed_t), intent(in) :: bodies(:)
    type(error_t), intent(inout) :: err
    integer, allocatable :: root(:), members(:), col(:), rowof(:), ti(:), tj(:), roff(:)
    real(wp), allocatable :: es(:), tv(:), v(:)
    type(sparse_cols_t) :: gs
    real(wp) :: c(NRIGID), res, hold, theta
    integer :: a, g, r, nm, ncol, k, i, i0, q, nz
    logical :: held
    character(len=:), allocatable :: names

    allocate (root(size(bodies)))
    root = floating_groups(contact_line, bodies)
    allocate (col(2*contact_line%m))
    do g = 1, size(bodies)
      if (bodies(g)%nrig == 0 .or. root(g) /= g) cycle
      members = pack([(a, a=1, size(bodies))], [(root(a) == g .and. bodies(a)%nrig > 0, a=1, size(bodies))])
      nm = size(members)
      if (nm < 2) cycle
      ! the union of the members' rows: column of each row in the stacked rows
      col = 0
      ncol = 0
      nz = 0
      allocate (roff(nm + 1))
      roff(1) = 0
      do k = 1, nm
        associate (cbody => bodies(members(k)))
          roff(k + 1) = roff(k) + cbody%nrig
          nz = nz + cbody%nrig*cbody%m
          do i = 1, cbody%m
            i0 = slot_row(cbody%slots(i), contact_line%m)
            if (col(i0) == 0) then
              ncol = ncol + 1
              col(i0) = ncol
            end if
          end do
        end associate
      end do
      r = roff(nm + 1)
      ! G of the group: a column per contact row, its entries in the rigid rows of the one or
      ! two members it touches (sparse: a group of n bodies has about n columns of 6 entries)
      allocate (ti(nz), tj(nz), tv(nz), es(r))
      nz = 0
      do k = 1, nm
        associate (cbody => bodies(members(k)))
          do i = 1, cbody%m
            i0 = slot_row(cbody%slots(i), contact_line%m)
            do q = 1, cbody%nrig
              nz = nz + 1
              ti(nz) = roff(k) + q
              tj(nz) = col(i0)
              tv(nz) = cbody%rg(q, i)
            end do
          end do
          es(roff(k) + 1:roff(k + 1)) = cbody%re
        end associate
      end do
      call gs%from_triplets(r, ncol, ti, tj, tv)
      deallocate (ti, tj, tv)
      names = group_names(members)
      ! every joint motion held (G G' v = theta S v with every theta > hold) exactly when
      ! G G' - hold S is positive definite: one Cholesky factor decides (dense r^3/3 up to
      ! NNLS_DENSE_MAX rows, sparse beyond: a chain's G G' is banded), the eigenproblem or
      ! inverse iteration only names the free motion when there is one. The threshold is
      ! HOLD_MIN / nm^2: a chain of nm bodies held at one end has its smallest theta near
      ! 2.5 / nm^2 (held, though weakly: 4e-5 for 249 blocks), while a motion the contact
      ! normals miss has theta at the normals' discretisation error
      hold = HOLD_MIN/real(nm, wp)**2
      call group_held(gs, members, roff, hold, held, theta, v, err)
      if (err%failed()) return
      if (.not. held .and. theta <= hold) then
        ! the free motion of the group, as its first body's part of it
        c = matmul(systems(members(1))%rig_coef, v(1:bodies(members(1))%nrig))
        if (nm == 2) then
          call err%set(ERR_INPUT, 'bodies '//names//' are both held only by contact, and together they are free: '// &
                'the pair can move as a whole ('//rigid_motion_name(systems(members(1)), c)//' of both) and nothing '// &
                'holds it; support one of the bodies against that rigid motion')
        else
          call err%set(ERR_INPUT, 'bodies '//names//' are all held only by contact, and together they are free: '// &
                'they can move as a whole ('//rigid_motion_name(systems(members(1)), c)//' of body '// &
                i2s(members(1))//') and nothing holds them; support one of the bodies against that rigid motion')
        end if
        return
      end if
      allocate (rowof(ncol))
      do i0 = 1, contact_line%m
        if (col(i0) > 0) rowof(col(i0)) = i0
      end do
      call admissible_nnls(contact_line, rowof, gs, es, res)
      deallocate (rowof)
      if (res > 1.0e-8_wp*norm2(es)) then
        call err%set(ERR_INPUT, 'bodies '//names//' are '//trim(merge('both', 'all ', nm == 2))// &
              ' held only by contact, and their loads cannot be balanced by compressive contact forces '// &
              'between them (unbalanced part '//sci(res)//'); support one of them')
        return
      end if
      deallocate (es, roff)
    end do

  contains

    !> Whether G G' - hold S is positive definite (S: the members' rreach blocks); when it
    !! is not, theta and v: the smallest theta of G G' v = theta S v and its motion (dense: LAPACK's
    !! generalized eigenproblem; sparse: inverse iteration with G G' + hold S).
    subroutine group_held(gs, members, roff, hold, held, theta, v, err)
      type(sparse_cols_t), intent(in) :: gs
      integer, intent(in) :: members(:), roff(:)
      real(wp), intent(in) :: hold
      logical, intent(out) :: held
      real(wp), intent(out) :: theta
      real(wp), allocatable, intent(out) :: v(:)
      type(error_t), intent(inout) :: err
      real(wp), allocatable :: gd(:, :), gg(:, :), sr(:, :), ev(:), bv(:), sv(:), gv(:)
      type(gram_t) :: gm
      type(error_t) :: ferr
      integer :: r, k, l, info, it, nb
      r = gs%nrow
      theta = huge(1.0_wp)
      if (r <= NNLS_DENSE_MAX) then
        allocate (gd(r, gs%ncol), sr(r, r), ev(r))
        gd = 0.0_wp
        do k = 1, gs%ncol
          do l = gs%ptr(k), gs%ptr(k + 1) - 1
            gd(gs%row(l), k) = gs%val(l)
          end do
        end do
        sr = 0.0_wp
        do k = 1, size(members)
          sr(roff(k) + 1:roff(k + 1), roff(k) + 1:roff(k + 1)) = bodies(members(k))%rreach
        end do
        gg = gram(gd)
        held = held_by_cholesky(gg, sr, r, hold)
        if (held) return
        call held_motions(gg, sr, r, ev, info)
        held = info /= 0
        theta = ev(1)
        v = gg(:, 1)
        return
      end if
      ! sparse: the blocks of -hold S, then of +hold S for the inverse iteration
      nb = sum([(bodies(members(k))%nrig**2, k=1, size(members))])
      allocate (bv(nb))
      l = 0
      do k = 1, size(members)
        associate (s => bodies(members(k))%rreach)
          bv(l + 1:l + size(s)) = reshape(s, [size(s)])
          l = l + size(s)
        end associate
      end do
      call gm%build(gs, roff + 1)
      call gm%factor(gs, spread(1.0_wp, 1, gs%ncol), -hold*bv, ferr)
      held = .not. ferr%failed()
      if (held) then
        call gm%free()
        return
      end if
      if (.not. gm%not_posdef) then
        call err%set(ERR_NUMERICAL, 'the check of the floating bodies '//group_names(members)//': '//ferr%message)
        return
      end if
      ! inverse iteration: v <- (G G' + hold S)^-1 S v converges to the smallest theta's motion
      call gm%factor(gs, spread(1.0_wp, 1, gs%ncol), hold*bv, ferr)
      if (ferr%failed()) then
        held = .true.      ! no motion to name (S singular along it): decided by the NNLS below
        call gm%free()
        return
      end if
      allocate (v(r))
      v = 1.0_wp
      do it = 1, 50
        sv = s_times(v)
        v = sv
        call gm%chol%solve(v, ferr)
        if (ferr%failed()) exit
        v = v/max(norm2(v), tiny(1.0_wp))
      end do
      sv = s_times(v)
      gv = gs%ttimes(v)
      ! the factor decided (G G' - hold S is not positive definite: some theta is below hold);
      ! the Rayleigh quotient only names the motion, and may sit above hold when the
      ! smallest theta are clustered
      theta = min(dot_product(gv, gv)/max(dot_product(v, sv), tiny(1.0_wp)), hold)
      call gm%free()

    end subroutine group_held

    !> S v (S: the members' rreach blocks).
    function s_times(x) result(y)
      real(wp), intent(in) :: x(:)
      real(wp) :: y(size(x))
      integer :: k
      do k = 1, size(members)
        y(roff(k) + 1:roff(k + 1)) = matmul(bodies(members(k))%rreach, x(roff(k) + 1:roff(k + 1)))
      end do
    end function s_times

  end subroutine check_groups

  !> G G' from G's nonzeros (a contact row's column touches the rigid rows of at most two
  !! bodies: a few products per column, not r^2 per column).
  function gram(gm) result(gg)
    real(wp), intent(in) :: gm(:, :)
    real(wp), allocatable :: gg(:, :)
    integer, allocatable :: nz(:)
    integer :: c, a, b, rr
    rr = size(gm, 1)
    allocate (gg(rr, rr))
    gg = 0.0_wp
    do c = 1, size(gm, 2)
      nz = pack([(a, a=1, rr)], gm(:, c) /= 0.0_wp)
      do b = 1, size(nz)
        do a = 1, size(nz)
          gg(nz(a), nz(b)) = gg(nz(a), nz(b)) + gm(nz(a), c)*gm(nz(b), c)
        end do
      end do
    end do
  end function gram

  !> G G' - hold S is positive definite (every joint rigid motion held; dpotrf).
  logical function held_by_cholesky(gg, s, r, hold) result(held)
    real(wp), intent(in) :: gg(:, :), s(:, :)
    integer, intent(in) :: r
    real(wp), intent(in) :: hold
    real(wp), allocatable :: a(:, :)
    integer :: info
    allocate (a(r, r))
    a = gg(1:r, 1:r) - hold*s(1:r, 1:r)
    call dpotrf('U', r, a, r, info)
    held = info == 0
  end function held_by_cholesky

  !> The groups of floating bodies that touch each other (connected by pairs of two
  !! floating bodies): root(a) is the lowest id of body a's group (a itself when alone or
  !! supported).
  function floating_groups(contact_line, bodies) result(root)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, allocatable :: root(:)
    integer :: p, a, b, k
    root = [(a, a=1, size(bodies))]
    do p = 1, contact_line%npair
      a = find(contact_line%pair_body(1, p))
      b = find(contact_line%pair_body(2, p))
      if (bodies(contact_line%pair_body(1, p))%nrig > 0 .and. bodies(contact_line%pair_body(2, p))%nrig > 0 &
          .and. a /= b) root(max(a, b)) = min(a, b)
    end do
    do k = 1, size(root)
      root(k) = find(k)
    end do

  contains

    !> The root of body x's group (path halving).
    integer function find(x)
      integer, intent(in) :: x
      find = x
      do while (root(find) /= find)
        root(find) = root(root(find))
        find = root(find)
      end do
    end function find

  end function floating_groups

  !> 'a and b' or 'a, b and c' (the bodies of a group); beyond 12 bodies the first five,
  !! '...', the last two and the count ('1, 2, 3, 4, 5, ..., 998 and 999 (999 bodies)').
  function group_names(ids) result(t)
    integer, intent(in) :: ids(:)
    character(len=:), allocatable :: t
    integer :: k, n
    n = size(ids)
    t = i2s(ids(1))
    do k = 2, n
      if (n > 12 .and. k > 5 .and. k < n - 1) then
        if (k == 6) t = t//', ...'
        cycle
      end if
      t = t//merge(' and ', ',    ', k == n)
      t = trim(t)//' '//i2s(ids(k))
    end do
    if (n > 12) t = t//' ('//i2s(n)//' bodies)'
  end function group_names

  !> A floating body with e = 0 (no load along its free motions) is pressed into the contact
  !! only when its deformation under the loads and prescribed displacements (the particular
  !! solutions: on each row, the b of both sides) closes the gap in a way no rigid motion can
  !! open again: the gaps h = g0 - b_s1 - b_s2 on its rows admit no motion alpha with
  !! G' alpha <= h (else the body can move off the contact and its position is undetermined).
  !! By Farkas: there is lam >= 0 with G lam = 0 and h' lam < 0, found by NNLS on the rows
  !! [G; h'/|h|] against (0, -1). ERR_INPUT with the sentence when the body is not pressed.
  subroutine check_pressed(systems, contact_line, bodies, err)
    type(body_system_t), intent(in) :: systems(:)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(error_t), intent(out) :: err                  !< ERR_INPUT when a body is not pressed
    real(wp), allocatable :: rows(:, :), target(:), lam(:), h(:), bs(:, :), ha(:)
    type(sparse_cols_t) :: gsp
    integer, allocatable :: root(:), unpressed(:), members(:)
    logical, allocatable :: loaded(:)
    real(wp) :: res
    integer :: a, r, m, i, g, k
    if (contact_line%m == 0) return
    allocate (bs(contact_line%m, 2))
    bs = 0.0_wp
    do a = 1, size(bodies)
      call scatter(bodies(a)%b, bodies(a)%slots, bs)
    end do
    h = contact_line%g0 - bs(:, 1) - bs(:, 2)
    allocate (root(size(bodies)), loaded(size(bodies)), unpressed(0))
    root = floating_groups(contact_line, bodies)
    ! the groups with a load: check_groups found it balanced by compressive forces through
    ! the group, which presses its members
    loaded = .false.
    do a = 1, size(bodies)
      if (bodies(a)%nrig > 0 .and. any(bodies(a)%re /= 0.0_wp)) loaded(root(a)) = .true.
    end do
    do a = 1, size(bodies)
      r = bodies(a)%nrig
      m = bodies(a)%m
      if (r == 0 .or. m == 0) cycle
      if (any(bodies(a)%re /= 0.0_wp) .or. loaded(root(a))) cycle
      allocate (rows(r + 1, m), target(r + 1), ha(m))
      do i = 1, m
        ha(i) = h(slot_row(bodies(a)%slots(i), contact_line%m))
      end do
      rows(1:r, :) = bodies(a)%rg
      rows(r + 1, :) = ha/max(maxval(abs(ha)), tiny(1.0_wp))
      target = 0.0_wp
      target(r + 1) = -1.0_wp
      call gsp%from_dense(rows)
      if (has_friction(contact_line)) gsp = cone_columns(contact_line, slot_row(bodies(a)%slots, contact_line%m), gsp)
      allocate (lam(gsp%ncol))
      call nnls(gsp, target, lam, res)
      if (.not. res <= 1.0e-8_wp) unpressed = [unpressed, a]
      deallocate (rows, target, lam, ha)
    end do
    ! not pressed by its own rows' gaps: perhaps through its floating neighbours (a plate
    ! clamped between two others by a third), decided on their group as a whole: one solve
    ! for all of a group's such bodies (a sum of the forces that reach each reaches all),
    ! and only when that fails one per body, to name it
    do i = 1, size(unpressed)
      a = unpressed(i)
      if (root(a) == 0) cycle
      g = root(a)
      members = pack(unpressed, root(unpressed) == g)
      res = group_pressing(contact_line, bodies, root, members, h)
      if (.not. res <= 1.0e-8_wp) then
        do k = 1, size(members)
          if (.not. group_pressing(contact_line, bodies, root, members(k:k), h) <= 1.0e-8_wp) exit
        end do
        a = members(min(k, size(members)))
        call err%set(ERR_INPUT, 'body '//i2s(a)//' is held only by contact (free: '//free_list(systems(a))//'), but no load '// &
              'presses it into the contact: its loads have no part along that motion, and its deformation '// &
              'under the loads and prescribed displacements leaves a rigid motion that lifts it off the '// &
              'contact, so its position is undetermined; load it towards the body it touches, or hold that '// &
              'rigid motion with a support: a ''clamped'' side, a ''roller'', or ux/uy on a group (&boundary)')
        return
      end if
      where (root(unpressed) == g) root(unpressed) = 0     ! the group is done
    end do

  end subroutine check_pressed

  !> Whether the floating bodies `targets` (of one group, root: floating_groups) are
  !! pressed into the contact through their group: is there a set of admissible contact
  !! forces lam on the group's rows, in equilibrium on every body of the group with tau times
  !! its load (G_b lam = tau e_b, tau >= 0), that some deformation or load drives (h'lam < 0
  !! or tau > 0, h the gaps after the particular deformations) and in which every target
  !! takes part (a force on one of its normal rows)? By NNLS on the rows [G_b ...; h'; s_a'
  !! per target] with the columns of lam (friction: the cone's generators), tau and a slack
  !! per inequality, against (0, -1, 1, ...): the residual, <= 1e-8 when such forces exist
  !! (the sum of the forces that reach each target reaches them all). A plate pressed by a bolt head
  !! through another plate has them; a body nothing reaches has not.
  real(wp) function group_pressing(contact_line, bodies, root, targets, h) result(res)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: root(:)
    integer, intent(in) :: targets(:)   !< the bodies that must take part (one group)
    real(wp), intent(in) :: h(:)
    type(sparse_cols_t) :: g, gc
    real(wp), allocatable :: x(:), target(:), e(:), tv(:)
    integer, allocatable :: col(:), rows(:), r0(:), tgt(:), ti(:), tj(:)
    integer :: b, i, k, nr, nc, mm, n, a, nt, nz, q
    real(wp) :: hs, es
    mm = contact_line%m
    nt = size(targets)
    a = targets(1)
    allocate (tgt(size(bodies)))
    tgt = 0
    tgt(targets) = [(i, i=1, nt)]
    ! the group's rows, each once (a row between two of its bodies is in both bodies' slots)
    allocate (col(mm))
    col = 0
    nc = 0
    nr = 0
    nz = 0
    allocate (r0(size(bodies)))
    r0 = 0
    do b = 1, size(bodies)
      if (root(b) /= root(a) .or. bodies(b)%nrig == 0) cycle
      r0(b) = nr
      nr = nr + bodies(b)%nrig
      nz = nz + (bodies(b)%nrig + 1)*bodies(b)%m
      do i = 1, bodies(b)%m
        k = slot_row(bodies(b)%slots(i), mm)
        if (col(k) == 0) then
          nc = nc + 1
          col(k) = nc
        end if
      end do
    end do
    allocate (rows(nc), e(nr))
    do k = 1, mm
      if (col(k) > 0) rows(col(k)) = k
    end do
    ! the entries: the members' rigid rows, the h row, a 1 in a target's row on its normal rows
    allocate (ti(nz + nc), tj(nz + nc), tv(nz + nc))
    e = 0.0_wp
    hs = max(maxval(abs(h)), tiny(1.0_wp))
    nz = 0
    do b = 1, size(bodies)
      if (root(b) /= root(a) .or. bodies(b)%nrig == 0) cycle
      e(r0(b) + 1:r0(b) + bodies(b)%nrig) = bodies(b)%re
      do i = 1, bodies(b)%m
        k = slot_row(bodies(b)%slots(i), mm)
        do q = 1, bodies(b)%nrig
          nz = nz + 1
          ti(nz) = r0(b) + q
          tj(nz) = col(k)
          tv(nz) = bodies(b)%rg(q, i)
        end do
        if (tgt(b) > 0 .and. contact_line%dir(k) == DIR_NORMAL) then
          nz = nz + 1
          ti(nz) = nr + 1 + tgt(b)
          tj(nz) = col(k)
          tv(nz) = 1.0_wp
        end if
      end do
    end do
    do i = 1, nc
      nz = nz + 1
      ti(nz) = nr + 1
      tj(nz) = i
      tv(nz) = h(rows(i))/hs
    end do
    call g%from_triplets(nr + 1 + nt, nc, ti(1:nz), tj(1:nz), tv(1:nz))
    if (has_friction(contact_line)) then
      gc = cone_columns(contact_line, rows, g)
    else
      gc = g
    end if
    n = gc%ncol
    es = norm2(e)
    if (es > 0.0_wp) then
      e = e/es
      es = 1.0_wp      ! tau presses only when the group has a load
    end if
    ! the columns of tau (the loads, scaled; counted as pressing), of the slack of the h row
    ! and of one slack per target's row
    call gc%push([[(i, i=1, nr)], nr + 1], [-e, -es])
    call gc%push([nr + 1], [1.0_wp])
    do i = 1, nt
      call gc%push([nr + 1 + i], [-1.0_wp])
    end do
    allocate (target(nr + 1 + nt), x(n + 2 + nt))
    target = 0.0_wp
    target(nr + 1) = -1.0_wp
    target(nr + 2:) = 1.0_wp
    call nnls(gc, target, x, res, merge(NNLS_ACTIVE_SET, NNLS_INTERIOR, nr <= NNLS_DENSE_MAX))
  end function group_pressing

  !> The columns of g (column i on contact row rows(i)) as generators of the admissible
  !! contact forces, for a non-negative least squares: a normal row without friction keeps
  !! its column (lam_n >= 0); a Coulomb pair's normal row i with its tangential row j gives
  !! g_i + mu g_j and g_i - mu g_j (lam_n (1, +-mu): exactly the cone |lam_t| <= mu lam_n);
  !! a Tresca pair keeps the normal column and gives +g_j and -g_j (the tangential force
  !! free of the normal one: its bound does not depend on it). In space a node's tangential
  !! force lies in a disc, and its generators are the CONE_SIDES directions
  !! (cos th_k t1 + sin th_k t2) / cos(pi / CONE_SIDES) of the polygon circumscribing the
  !! disc: an outer approximation, exact to 1 / cos(pi / CONE_SIDES) - 1 = 1.2e-3 relative
  !! (a load up to that much beyond the friction limit passes the check, and the solve then
  !! says it does not converge). With tres (one entry per column of gc): the Tresca
  !! tangential row whose bound the column shares (its tangent-1 row in space), 0 for none.
  function cone_columns(contact_line, rows, g, mu_scale, tres) result(gc)
    type(interface_t), intent(in) :: contact_line
    integer, intent(in) :: rows(:)
    type(sparse_cols_t), intent(in) :: g
    real(wp), intent(in), optional :: mu_scale   !< Coulomb's mu times this (default 1)
    integer, allocatable, intent(out), optional :: tres(:)
    type(sparse_cols_t) :: gc
    integer, allocatable :: tcol(:, :), cr(:), tr(:)
    real(wp), allocatable :: cv(:), dir(:, :), nd_dir(:, :)
    integer :: i, k, p, q, nc
    real(wp) :: sc, t
    sc = 1.0_wp
    if (present(mu_scale)) sc = mu_scale
    ! the directions of a node's tangential force: +-t in the plane, the polygon in space
    if (NDIM == 2) then
      dir = reshape([1.0_wp, -1.0_wp], [1, 2])
    else
      allocate (dir(2, CONE_SIDES))
      do q = 1, CONE_SIDES
        dir(:, q) = [cos(2.0_wp*PI*(q - 1)/CONE_SIDES), sin(2.0_wp*PI*(q - 1)/CONE_SIDES)]/cos(PI/CONE_SIDES)
      end do
    end if
    ! at most size(dir, 2) columns per row: tres's entries filled in place (nc of them)
    allocate (tcol(NDIM - 1, contact_line%m), tr(size(dir, 2)*size(rows)))
    nc = 0
    tcol = 0
    do i = 1, size(rows)
      if (contact_line%dir(rows(i)) > DIR_NORMAL) tcol(contact_line%dir(rows(i)), contact_line%nrow(rows(i))) = i
    end do
    call gc%init(g%nrow, size(dir, 2)*(g%ptr(g%ncol + 1) - 1))
    do i = 1, size(rows)
      k = rows(i)
      p = contact_line%pair_of(k)
      if (contact_line%dir(k) > DIR_NORMAL) then
        ! a Tresca node's generators at its first tangential row
        if (contact_line%pair_friction(p) == FRICTION_COULOMB .or. i /= first_tangent(contact_line%nrow(k))) cycle
        call node_directions(contact_line%nrow(k))
        do q = 1, size(nd_dir, 2)
          allocate (cr(0), cv(0))
          call add_tangents(contact_line%nrow(k), q, 1.0_wp)
          call gc%push(cr, cv)
          nc = nc + 1
          tr(nc) = k
          deallocate (cr, cv)
        end do
      else if (any(tcol(:, k) > 0) .and. contact_line%pair_friction(p) == FRICTION_COULOMB) then
        ! divided by sqrt(1 + (mu |d|)^2): the same cone, columns of one size for any mu
        t = sc*contact_line%pair_mu(p)
        call node_directions(k)
        do q = 1, size(nd_dir, 2)
          cr = g%row(g%ptr(i):g%ptr(i + 1) - 1)
          cv = g%val(g%ptr(i):g%ptr(i + 1) - 1)
          call add_tangents(k, q, t)
          call gc%push(cr, cv/sqrt(1.0_wp + (t*norm2(nd_dir(:, q)))**2))
          nc = nc + 1
          tr(nc) = 0
        end do
      else
        call gc%push(g%row(g%ptr(i):g%ptr(i + 1) - 1), g%val(g%ptr(i):g%ptr(i + 1) - 1))
        nc = nc + 1
        tr(nc) = 0
      end if
    end do
    if (present(tres)) tres = tr(1:nc)

  contains

    !> The position in rows of node row n's first tangential row.
    integer function first_tangent(n)
      integer, intent(in) :: n
      first_tangent = tcol(findloc(tcol(:, n) > 0, .true., 1), n)
    end function first_tangent

    !> nd_dir: the directions of node row n's tangential force: the polygon when it has two
    !! tangential rows, +-1 along its one row otherwise (the plane, or a plane of symmetry).
    subroutine node_directions(n)
      integer, intent(in) :: n
      if (count(tcol(:, n) > 0) == NDIM - 1) then
        nd_dir = dir
      else
        nd_dir = 0.0_wp*dir(:, 1:2)
        nd_dir(findloc(tcol(:, n) > 0, .true., 1), :) = [1.0_wp, -1.0_wp]
      end if
    end subroutine node_directions

    !> cr, cv plus tt times direction q (nd_dir) of node row n's tangential columns.
    subroutine add_tangents(n, q, tt)
      integer, intent(in) :: n, q
      real(wp), intent(in) :: tt
      integer :: j
      do j = 1, NDIM - 1
        if (tcol(j, n) > 0) call add_column(tcol(j, n), tt*nd_dir(j, q))
      end do
    end subroutine add_tangents

    !> cr, cv plus tt times column b.
    subroutine add_column(b, tt)
      integer, intent(in) :: b
      real(wp), intent(in) :: tt
      integer :: l, c, n
      n = size(cr)
      do l = g%ptr(b), g%ptr(b + 1) - 1
        c = findloc(cr(1:n), g%row(l), 1)
        if (c > 0) then
          cv(c) = cv(c) + tt*g%val(l)
        else
          cr = [cr, g%row(l)]
          cv = [cv, tt*g%val(l)]
        end if
      end do
    end subroutine add_column

  end function cone_columns

  !> nnls(g, e) over the admissible contact forces of the rows `rows` (g's columns): the
  !! cone's generators (`cone_columns`), and for a Tresca node its bound too, |lam_t| <= t =
  !! slip_bound x tributary length: lam_t = t sum_q s_q d_q over the node's generators d_q
  !! with sum_q s_q + slack = 1, one more equation per such node, scaled by |e| so that the
  !! residual weighs a violated bound like an unbalanced load of |e|. res: the residual.
  subroutine admissible_nnls(contact_line, rows, g, e, res, mu_scale)
    type(interface_t), intent(in) :: contact_line
    integer, intent(in) :: rows(:)
    type(sparse_cols_t), intent(in) :: g
    real(wp), intent(in) :: e(:)
    real(wp), intent(out) :: res
    real(wp), intent(in), optional :: mu_scale
    type(sparse_cols_t) :: gc, ga
    real(wp), allocatable :: ea(:), x(:), tb(:)
    integer, allocatable :: tres(:), bound_of(:)
    integer :: c, k, nt, r, p
    real(wp) :: w, t, gn
    if (.not. has_friction(contact_line)) then
      allocate (x(g%ncol))
      call nnls(g, e, x, res)
      return
    end if
    gc = cone_columns(contact_line, rows, g, mu_scale, tres)
    nt = 0
    if (size(tres) > 0) nt = count(tres > 0)
    if (nt == 0) then
      allocate (x(gc%ncol))
      call nnls(gc, e, x, res)
      return
    end if
    r = g%nrow
    w = max(norm2(e), tiny(1.0_wp))
    ! the Tresca nodes in the order of their first generator, each with its bound, no larger
    ! than 1e3 |e| / |its first generator| (a bound beyond that does not bind a balance of |e|,
    ! and a slip_bound of 1e20 would only spoil the least squares)
    allocate (bound_of(contact_line%m), tb(contact_line%m))
    bound_of = 0
    nt = 0
    do c = 1, gc%ncol
      k = tres(c)
      if (k == 0) cycle
      if (bound_of(k) > 0) cycle
      nt = nt + 1
      bound_of(k) = nt
      p = contact_line%pair_of(k)
      t = contact_line%pair_slip(p)*contact_line%trib(k)
      gn = norm2(gc%val(gc%ptr(c):gc%ptr(c + 1) - 1))
      ! (a generator of no length, or one so short that the cap would overflow: no cap)
      if (gn > 1.0e3_wp*(w/huge(1.0_wp))) t = min(t, 1.0e3_wp*w/gn)
      tb(nt) = t
    end do
    allocate (ea(r + nt), x(gc%ncol + nt))
    ea(1:r) = e
    ea(r + 1:) = w
    call ga%init(r + nt, size(gc%val) + 3*nt + gc%ncol)
    ! gc's columns in order; each Tresca generator scaled by its node's bound
    do c = 1, gc%ncol
      associate (rc => gc%row(gc%ptr(c):gc%ptr(c + 1) - 1), vc => gc%val(gc%ptr(c):gc%ptr(c + 1) - 1))
        if (tres(c) > 0) then
          call ga%push([rc, r + bound_of(tres(c))], [vc*tb(bound_of(tres(c))), w])
        else
          call ga%push(rc, vc)
        end if
      end associate
    end do
    do k = 1, nt
      call ga%push([r + k], [w])
    end do
    ! the method by the rigid rows (the bound rows, one per Tresca node, do not make the
    ! active set method's problem harder to decide, only longer)
    call nnls(ga, ea, x, res, merge(NNLS_ACTIVE_SET, NNLS_INTERIOR, r <= NNLS_DENSE_MAX))

  end subroutine admissible_nnls

  !> theta ascending and the eigenvectors (in gg) of G G' v = theta S v (S: rreach): how much of
  !! each motion's reach on the contact is normal to it. S singular (a motion that does not
  !! move the contact nodes at all): info /= 0 from dsygv, and then that motion has theta = 0
  !! (dsyev of G G' alone decides, with a zero threshold scale).
  subroutine held_motions(gg, s, r, theta, info)
    real(wp), intent(inout) :: gg(:, :)
    real(wp), intent(in) :: s(:, :)
    integer, intent(in) :: r
    real(wp), intent(out) :: theta(:)
    integer, intent(out) :: info
    real(wp), allocatable :: b(:, :), g0(:, :), work(:)
    real(wp) :: wq(1)
    integer :: lwork
    allocate (g0(r, r), b(r, r))
    g0 = gg(1:r, 1:r)
    b = s(1:r, 1:r)
    ! the workspace LAPACK asks for (a fixed 64 was too small from r = 22 on: dsygv and
    ! dsyev refused it, printed "illegal value" and the group's check was skipped)
    call dsygv(1, 'V', 'U', r, gg, r, b, r, theta, wq, -1, info)
    lwork = max(3*r, int(wq(1)))
    allocate (work(lwork))
    call dsygv(1, 'V', 'U', r, gg, r, b, r, theta, work, lwork, info)
    if (info /= 0) then
      gg(1:r, 1:r) = g0
      call dsyev('V', 'U', r, gg, r, theta, work, lwork, info)
      if (info == 0) theta(1) = 0.0_wp
    end if
  end subroutine held_motions

  !> The rigid motions a body's supports leave free, in words.
  function free_list(system) result(s)
    type(body_system_t), intent(in) :: system
    character(len=:), allocatable :: s
    integer :: k
    s = ''
    do k = 1, system%nrig
      if (k > 1) s = s//', '
      s = s//rigid_motion_name(system, system%rig_coef(:, k))
    end do
  end function free_list

  !> The fixing DOFs in words: 'node 12 uy, node 40 ux' ('uz' in 3D), by the nodes' tags (a
  !! mesh file's node tags; a rectangle's node numbers).
  function fixing_list(system, node_tag) result(s)
    type(body_system_t), intent(in) :: system
    integer, intent(in) :: node_tag(:)          !< (nodes) the tag of each node of the body's mesh
    character(len=:), allocatable :: s
    character(len=*), parameter :: AXES = 'xyz'
    integer :: k
    s = ''
    do k = 1, system%nrig
      if (k > 1) s = s//', '
      s = s//'node '//i2s(node_tag(dof_node(system%fixing(k))))//' u'//AXES(dof_comp(system%fixing(k)):dof_comp(system%fixing(k)))
    end do
  end function fixing_list

end module floating
