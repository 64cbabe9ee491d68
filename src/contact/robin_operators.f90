!> The Robin operators of the outer iteration (doc/method.md, "Method as implemented",
!! "Several bodies and contact pairs"): on every contact row, side 1's obstacle moves by
!! corr(:, 1), side 2's by -corr(:, 2), from the imbalance d = lam_side1 - lam_side2.
!! 'steklov' (the paper's: each body's flexibility on its own imbalance over all its rows,
!! moving its partners' obstacles; two bodies: S_1 = F_2, S_2 = F_1), 'constant'
!! (S = alpha M^-1) and 'harmonic' (per pair, S = 2 (F_A^-1 + F_B^-1)^-1 of the pair's
!! blocks) extend one abstract type; they differ in the correction itself, the inner
!! tolerance, the bound of lambda_max(F_a) the subproblems use, and the proximal term of a
!! body with a singular F_a. `new_robin_operator` is the one place that picks the operator
!! from the decoded setting (config's ROBIN_*).
module robin_operators
  use kinds, only: wp, ip
  use config, only: solver_cfg_t, ROBIN_CONSTANT, ROBIN_HARMONIC
  use linop, only: dense_op_t, dense_op_init, dense_op_take, symmetrize
  use cholesky, only: chol_t, FACT_CHOLMOD, ORD_AMD
  use lapack, only: dgemm, dposv, dgesv, dsyevd, dgesvd, dpotrf, dpotri, dpocon, dtrsm, dsyrk, dsymv, dtrsv, tiles_begin, tiles_end
  use iso_c_binding, only: c_long
  use mprgp, only: lambda_max_estimate
  use contact_interface, only: interface_t, has_friction, slot_row, slot_side, DIR_NORMAL
  use condense, only: body_condensed_t
  use contact_common, only: pair_positions, body_threads
  use sorting, only: largest_first, merge_sort_by_keys
  use errors, only: error_t, ERR_NUMERICAL
  use strings, only: i2s
  implicit none (type, external)
  private

  integer, parameter :: POWER_ITS = 10   !< power iterations for each body's lambda_max (harmonic operator)
  !> a body's F with an estimated reciprocal 1-norm condition above this has its stiffness
  !! from a Cholesky factorization: no eigenvalue of Z' F Z is near body_stiffness's cut of
  !! 1e-10 of the largest unless the estimate is off by 1e4
  real(wp), parameter :: RCOND_CHOLESKY = 1.0e-6_wp

  !> A Robin operator: the correction of the obstacles and what goes with it.
  type, abstract, public :: robin_operator_t
    !> The first failure of `apply` (a library's solve inside it): the outer loop stops on it
    !! as a numerical failure (exit 3), with this message
    type(error_t) :: failure
  contains
    !> Build the correction once, before the outer loop.
    procedure(setup_iface), deferred :: setup
    !> corr(:, 1), corr(:, 2) from d; count grows by the Hessian-sized products.
    procedure(apply_iface), deferred :: apply
    !> The inner tolerance of outer iteration `it` (default: follows the outer progress).
    procedure :: inner_tolerance => progress_tolerance
    !> A bound of lambda_max(F_a) for MPRGP (default: the row-sum norm, no product).
    procedure :: body_lambda_max => row_sum_bound
    !> The proximal term Pi_a of a body whose F_a is singular (default: its partners' F).
    procedure :: proximal_term => other_flexibility
  end type robin_operator_t

  abstract interface
    !> Build the correction; err (ERR_NUMERICAL) when it cannot be built.
    subroutine setup_iface(self, solver, contact_line, bodies, flexibility, err)
      import :: robin_operator_t, solver_cfg_t, interface_t, body_condensed_t, dense_op_t, error_t
      class(robin_operator_t), intent(inout) :: self
      type(solver_cfg_t), intent(in) :: solver
      type(interface_t), intent(in) :: contact_line
      type(body_condensed_t), intent(in) :: bodies(:)
      type(dense_op_t), target, intent(in) :: flexibility(:)    !< F_a as operators (kept by reference)
      type(error_t), intent(out) :: err
    end subroutine setup_iface

    !> The corrections of both sides of every row from the imbalance d of outer iteration it.
    subroutine apply_iface(self, d, corr, count, it)
      import :: robin_operator_t, wp
      class(robin_operator_t), intent(inout) :: self
      real(wp), intent(in) :: d(:)
      real(wp), intent(out) :: corr(:, :)
      integer, intent(inout) :: count
      integer, intent(in) :: it
    end subroutine apply_iface
  end interface

  !> 'steklov': each body's flexibility on its own imbalance (its force minus its partners'
  !! on its rows) corrects its partners' obstacles (a floating body's on self-equilibrated
  !! forces only: `projected_flex`).
  type, extends(robin_operator_t), public :: steklov_operator_t
    type(dense_op_t), pointer :: flexibility(:) => null()   !< F_a (the subproblems' operators)
    type(dense_op_t), allocatable :: projected(:)  !< P_a F_a P_a of a floating body (n = 0: none)
    type(slots_t), allocatable :: at(:)            !< each body's slots in the side layout
  contains
    procedure :: setup => steklov_setup
    procedure :: apply => steklov_apply
  end type steklov_operator_t

  !> 'constant': alpha M^-1, M the tributary lengths.
  type, extends(robin_operator_t), public :: constant_operator_t
    real(wp) :: alpha = 0.0_wp               !< Robin parameter [length/stress]
    real(wp), allocatable :: w(:)            !< (m) tributary lengths [length]
  contains
    procedure :: setup => constant_setup
    procedure :: apply => constant_apply
  end type constant_operator_t

  !> 'harmonic': per pair, S = 2 F_A (F_A+F_B)^-1 F_B of the pair's blocks of its two
  !! bodies' flexibilities, for both obstacles (contrast-robust).
  type, extends(robin_operator_t), public :: harmonic_operator_t
    type(dense_op_t), allocatable :: s(:)    !< S of each pair, formed (n = 0: factored or in a group)
    integer, allocatable :: rows(:, :)       !< (2, pairs) each pair's rows, first and last
    type(group_op_t), allocatable :: group(:) !< S of each group of pairs joined by their bodies
    type(pair_factor_t), allocatable :: fac(:) !< S of each pair applied from its factors until formed
    type(dense_op_t), pointer :: flexibility(:) => null()   !< the bodies' F_a (the factored S's products)
  contains
    procedure :: setup => harmonic_setup
    procedure :: apply => harmonic_apply
    procedure :: inner_tolerance => harmonic_tolerance
    procedure :: body_lambda_max => power_estimate
    procedure :: proximal_term => kernel_proximal
  end type harmonic_operator_t

  !> A body of a two-body pair: its flexibility and, for a floating body, its equilibrium rows.
  type :: block_t
    real(wp), allocatable :: f(:, :)
    real(wp), allocatable :: g(:, :)
    integer :: nrig = 0
  end type block_t

  !> A body's stiffness on its contact rows and its infinitely stiff directions.
  type :: stiffness_t
    real(wp), allocatable :: k(:, :)
    real(wp), allocatable :: inf(:, :)
  end type stiffness_t

  !> S = 2 F_s - 2 F_s (F_1 + F_2)^-1 F_s of a two-body pair, F_s the flexibility of the
  !! stiffer body (smaller trace), held as the Cholesky factor L of F_1 + F_2 and applied by two
  !! products with F_s and two triangular solves, until the outer iteration `form_at`, from
  !! which S is formed (harmonic_apply).
  type, public :: pair_factor_t
    real(wp), allocatable :: l(:, :)         !< L, lower triangle (unallocated: S formed or not factored)
    integer :: stiff = 0                     !< the body whose F is F_s
    integer :: form_at = 0                   !< the outer iteration that forms S
  end type pair_factor_t

  !> The harmonic operator of a group of pairs joined through bodies in several pairs:
  !! S = 2 K^-1 on the group's rows, K the assembled stiffness of its bodies.
  type, public :: group_op_t
    integer, allocatable :: rows(:)          !< the group's rows (ascending)
    type(dense_op_t) :: s                    !< S on those rows (a group of at most GROUP_DENSE_MAX rows)
    logical :: sparse = .false.              !< S = 2 K^-1 applied by kf's solves instead
    type(chol_t) :: kf                       !< sparse Cholesky factor of K (CHOLMOD)
  end type group_op_t

  !> The most rows a group's dense K may have (1 GB of K and S at 8192; a Cholesky factor
  !! and inverse of 4096 rows take about 10 s on one core): a larger group keeps K sparse
  !! (its bodies' blocks) and applies S = 2 K^-1 by CHOLMOD solves (doc/method.md).
  integer, parameter :: GROUP_DENSE_MAX = 4096

  !> A body's slots in the side layout (body_condensed_t%slots).
  type :: slots_t
    integer, allocatable :: v(:)
  end type slots_t

  public :: new_robin_operator, progress_rtol, range_proximal

contains

  !> The Robin operator of a ROBIN_* code (config), not yet set up.
  function new_robin_operator(kind) result(op)
    integer, intent(in) :: kind                      !< ROBIN_*
    class(robin_operator_t), allocatable :: op
    select case (kind)
    case (ROBIN_CONSTANT)
      allocate (constant_operator_t :: op)
    case (ROBIN_HARMONIC)
      allocate (harmonic_operator_t :: op)
    case default
      allocate (steklov_operator_t :: op)
    end select
  end function new_robin_operator

  ! ---- defaults --------------------------------------------------------------------------

  !> The inner tolerance following the outer progress, min(increment, residual) of the
  !! previous iteration, times inner_factor, clamped to [inner_rtol_min, inner_rtol_max].
  real(wp) function progress_tolerance(self, solver, it, m, progress, lmax) result(rtol_in)
    class(robin_operator_t), intent(in) :: self
    type(solver_cfg_t), intent(in) :: solver       !< solver settings
    integer, intent(in) :: it                      !< outer iteration
    integer, intent(in) :: m                       !< contact nodes
    real(wp), intent(in) :: progress               !< min(increment, residual) of iteration it - 1
    real(wp), intent(in) :: lmax(:)                !< bounds of lambda_max(F_a), per body
    rtol_in = progress_rtol(solver, it, progress)
  end function progress_tolerance

  !> clamp(inner_factor x progress, inner_rtol_min, inner_rtol_max); inner_rtol_max at the
  !! first iteration (doc/method.md, "Inner tolerance").
  pure real(wp) function progress_rtol(solver, it, progress) result(rtol_in)
    type(solver_cfg_t), intent(in) :: solver       !< solver settings
    integer, intent(in) :: it                      !< outer iteration
    real(wp), intent(in) :: progress               !< min(increment, residual) of iteration it - 1
    if (it == 1) then
      rtol_in = solver%inner_rtol_max
    else
      rtol_in = min(solver%inner_rtol_max, max(solver%inner_rtol_min, solver%inner_factor*progress))
    end if
  end function progress_rtol

  !> The row-sum norm |F_a|_inf, an upper bound of lambda_max for a symmetric matrix (so
  !! alpha_bar = 1.9/|F_a|_inf is admissible without MPRGP's guard): one pass over F_a, no
  !! product (nmv = 0).
  real(wp) function row_sum_bound(self, flexibility, flex, nmv) result(lmax)
    class(robin_operator_t), intent(in) :: self
    type(dense_op_t), intent(inout) :: flexibility     !< F_a as an operator
    real(wp), intent(in) :: flex(:, :)                 !< F_a
    integer, intent(out) :: nmv                        !< products with F_a taken
    lmax = maxval(sum(abs(flex), dim=1))
    nmv = 0
  end function row_sum_bound

  !> Pi_a = the partners' flexibilities on body a's rows, pair by pair (two bodies: F_o,
  !! the other body's): F_a + Pi_a is then the monolithic Hessian's part on those rows,
  !! definite (doc/method.md, "Non-matching and curved contact surfaces: dual mortar").
  subroutine other_flexibility(self, contact_line, bodies, a, p)
    class(robin_operator_t), intent(in) :: self
    type(interface_t), intent(in) :: contact_line      !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)    !< condensed bodies
    integer, intent(in) :: a                           !< the body with a singular F_a
    real(wp), intent(out) :: p(:, :)                   !< Pi_a
    p = partner_flex(contact_line, bodies, a)
  end subroutine other_flexibility

  !> Body a's partners' flexibilities on its rows: for each pair of a, the block of the
  !! partner's F on the pair's rows, in a's positions; zero between pairs.
  function partner_flex(contact_line, bodies, a) result(p)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: a
    real(wp), allocatable :: p(:, :)
    integer :: q, o, ra(2), ro(2)
    allocate (p(bodies(a)%m, bodies(a)%m))
    p = 0.0_wp
    do q = 1, contact_line%npair
      if (all(contact_line%pair_body(:, q) /= a)) cycle
      o = sum(contact_line%pair_body(:, q)) - a
      ra = pair_positions(bodies(a), contact_line, q)
      ro = pair_positions(bodies(o), contact_line, q)
      if (ra(2) < ra(1)) cycle
      p(ra(1):ra(2), ra(1):ra(2)) = bodies(o)%flex(ro(1):ro(2), ro(1):ro(2))
    end do
  end function partner_flex

  ! ---- steklov ---------------------------------------------------------------------------

  subroutine steklov_setup(self, solver, contact_line, bodies, flexibility, err)
    class(steklov_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(dense_op_t), target, intent(in) :: flexibility(:)
    type(error_t), intent(out) :: err
    integer :: a
    allocate (self%projected(size(bodies)), self%at(size(bodies)))
    do a = 1, size(bodies)
      self%projected(a)%n = 0
      self%at(a)%v = bodies(a)%slots
      if (bodies(a)%nrig > 0 .and. bodies(a)%m > 0) call dense_op_init(self%projected(a), projected_flex(bodies(a)))
    end do
    self%flexibility => flexibility
  end subroutine steklov_setup

  !> Body b's own imbalance d_b (+d on its side-1 rows, -d on its side-2 rows), y = F_b d_b,
  !! and the partner's obstacle on each of those rows moves by -y (corr(:, 1) = -y where b
  !! is side 2, corr(:, 2) = y where it is side 1). Two bodies: corr(:, 1) = F_2 d,
  !! corr(:, 2) = F_1 d.
  subroutine steklov_apply(self, d, corr, count, it)
    class(steklov_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    integer, intent(in) :: it                       !< outer iteration
    real(wp), allocatable :: db(:), y(:)
    integer :: b, k, m, sl, row
    m = size(d)
    do b = 1, size(self%at)
      associate (slots => self%at(b)%v)
        if (size(slots) == 0) cycle
        allocate (db(size(slots)), y(size(slots)))
        do k = 1, size(slots)
          sl = slots(k)
          if (sl > m) then
            db(k) = -d(sl - m)
          else
            db(k) = d(sl)
          end if
        end do
        if (self%projected(b)%n > 0) then
          call self%projected(b)%apply(db, y)
        else
          call self%flexibility(b)%apply(db, y)
        end if
        do k = 1, size(slots)
          sl = slots(k)
          if (sl > m) then
            row = sl - m
            corr(row, 1) = -y(k)
          else
            corr(sl, 2) = y(k)
          end if
        end do
        deallocate (db, y)
        count = count + 1
      end associate
    end do
  end subroutine steklov_apply

  !> P F_a P with P = I - G_a'(G_a G_a')^-1 G_a, the orthogonal projector on the forces that
  !! G_a sees as balanced: a floating body's F_a depends on its fixing DOFs by terms in G_a'
  !! (rigid motions), its response to a self-equilibrated force does not
  !! (doc/method.md, "Bodies held only by contact").
  function projected_flex(cbody) result(pf)
    type(body_condensed_t), intent(in) :: cbody
    real(wp), allocatable :: pf(:, :), q(:, :), gg(:, :), y(:, :)
    integer :: m, r, info
    m = cbody%m
    r = cbody%nrig
    allocate (pf(m, m), q(r, m), gg(r, r), y(m, m))
    ! q = (G G')^-1 G, so that P x = x - G' (q x)
    gg = matmul(cbody%rg, transpose(cbody%rg))
    q = cbody%rg
    call dposv('U', r, m, gg, r, q, r, info)
    ! y = P F = F - G' (q F);  pf = y P = y - (y q') G
    y = cbody%flex - matmul(transpose(cbody%rg), matmul(q, cbody%flex))
    pf = y - matmul(matmul(y, transpose(q)), cbody%rg)
    call symmetrize(pf)
  end function projected_flex

  ! ---- constant --------------------------------------------------------------------------

  subroutine constant_setup(self, solver, contact_line, bodies, flexibility, err)
    class(constant_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(dense_op_t), target, intent(in) :: flexibility(:)
    type(error_t), intent(out) :: err
    self%alpha = solver%alpha
    self%w = contact_line%trib
  end subroutine constant_setup

  !> corr(:, 1) = corr(:, 2) = alpha d ./ w (no Hessian-sized product).
  subroutine constant_apply(self, d, corr, count, it)
    class(constant_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    integer, intent(in) :: it                       !< outer iteration
    corr(:, 1) = self%alpha*d/self%w
    corr(:, 2) = corr(:, 1)
  end subroutine constant_apply

  ! ---- harmonic --------------------------------------------------------------------------

  !> S of each pair. A pair whose two bodies are in no other pair (two bodies): from their
  !! whole F (and, for a floating body, its equilibrium rows: `harmonic_floating`). Else
  !! each body's stiffness on all its rows (`body_stiffness`: its other pairs' rows held,
  !! which is what holds a floating body in a stack), its block on the pair's rows, and
  !! S = 2 (Sigma_A + Sigma_B)^-1 of the blocks (`parallel_flex`).
  subroutine harmonic_setup(self, solver, contact_line, bodies, flexibility, err)
    class(harmonic_operator_t), intent(inout) :: self
    type(solver_cfg_t), intent(in) :: solver
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(dense_op_t), target, intent(in) :: flexibility(:)
    type(error_t), intent(out) :: err
    real(wp), allocatable :: s(:, :)
    integer :: p, info, side, a, k
    integer, allocatable :: npairs(:), order(:), stiff_info(:), pair_info(:)
    logical, allocatable :: needs_stiffness(:)
    type(block_t) :: blk(2)
    type(stiffness_t), allocatable :: stiff(:)
    character(len=100) :: emsg
    allocate (self%s(contact_line%npair), self%rows(2, contact_line%npair), npairs(size(bodies)), stiff(size(bodies)))
    allocate (self%fac(contact_line%npair))
    self%flexibility => flexibility
    npairs = 0
    do p = 1, contact_line%npair
      npairs(contact_line%pair_body(:, p)) = npairs(contact_line%pair_body(:, p)) + 1
    end do
    ! the stiffness of every body in a pair with other pairs, once, before the pairs: the
    ! bodies on the threads, largest first (an eigendecomposition of its m_a x m_a block each)
    allocate (needs_stiffness(size(bodies)), stiff_info(size(bodies)))
    needs_stiffness = .false.
    stiff_info = 0
    do p = 1, contact_line%npair
      if (contact_line%pair_ptr(p + 1) <= contact_line%pair_ptr(p)) cycle
      if (all(npairs(contact_line%pair_body(:, p)) == 1)) cycle
      needs_stiffness(contact_line%pair_body(:, p)) = .true.
    end do
    order = largest_first([(bodies(a)%m, a=1, size(bodies))])
    !$omp parallel do num_threads(body_threads()) schedule(dynamic, 1) private(a) if (count(needs_stiffness) > 1)
    do k = 1, size(bodies)
      a = order(k)
      if (needs_stiffness(a)) call body_stiffness(bodies(a)%flex, bodies(a)%rg, stiff(a)%k, stiff(a)%inf, stiff_info(a))
    end do
    !$omp end parallel do
    ! the pairs on the threads (each S from its own blocks), the first failing pair reported
    allocate (pair_info(contact_line%npair))
    pair_info = 0
    do p = 1, contact_line%npair
      self%rows(:, p) = [contact_line%pair_ptr(p), contact_line%pair_ptr(p + 1) - 1]
      self%s(p)%n = 0
    end do
    !$omp parallel do num_threads(body_threads()) schedule(dynamic, 1) private(p, s, info, side, a, blk) &
    !$omp if (contact_line%npair > 1)
    do p = 1, contact_line%npair
      if (self%rows(2, p) < self%rows(1, p)) cycle
      info = 0
      if (all(npairs(contact_line%pair_body(:, p)) == 1)) then
        associate (f1 => bodies(contact_line%pair_body(1, p))%flex, f2 => bodies(contact_line%pair_body(2, p))%flex)
          if (any(bodies(contact_line%pair_body(:, p))%nrig > 0)) then
            do side = 1, 2
              a = contact_line%pair_body(side, p)
              blk(side)%f = bodies(a)%flex
              blk(side)%nrig = bodies(a)%nrig
              if (bodies(a)%nrig > 0) blk(side)%g = bodies(a)%rg
            end do
            call harmonic_floating(blk, s, info)
            ! a singular F (a mortar master coarser than the slave): no inverse of it
            if (info /= 0 .and. pair_singular(p)) call harmonic_singular(blk, s, info)
          else if (has_friction(contact_line)) then
            ! with friction: S of the normal rows and S of the tangential rows apart (below)
            call harmonic_by_kind(f1, f2, contact_line%dir(self%rows(1, p):self%rows(2, p)) > DIR_NORMAL, s, info)
          else
            ! factored; formed once the run is long enough to repay it (pair_factor_t)
            call harmonic_factor(f1, f2, self%fac(p), info)
            if (info == 0) self%fac(p)%stiff = contact_line%pair_body(self%fac(p)%stiff, p)
            pair_info(p) = info
            cycle
          end if
        end associate
      else
        ! in a group: below
        pair_info(p) = 0
        cycle
      end if
      pair_info(p) = info
      if (info == 0) call dense_op_take(self%s(p), s)
    end do
    !$omp end parallel do
    call group_operators(self, contact_line, bodies, stiff, stiff_info, npairs, err)
    if (err%failed()) return
    do p = 1, contact_line%npair
      info = pair_info(p)
      if (info /= 0 .and. any(bodies(contact_line%pair_body(:, p))%nrig > 0) .and. pair_singular(p)) then
        call err%set(ERR_NUMERICAL, 'harmonic operator: a body held only by contact is a mortar master coarser than '// &
                     'the slave (singular F): make it the slave (&contact slave), or use steklov or monolithic')
        return
      else if (info /= 0) then
        write (emsg, '(a,i0)') 'harmonic Robin operator: F_1 + F_2 is not positive definite, info = ', info
        if (contact_line%npair > 1) write (emsg, '(a,i0,a,i0)') 'harmonic Robin operator: pair ', p, &
          ': F_A + F_B is not positive definite, info = ', info
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
    end do

  contains

    !> A body of pair q has a singular F (rank below its rows).
    logical function pair_singular(q)
      integer, intent(in) :: q
      integer :: sd
      pair_singular = any([(bodies(contact_line%pair_body(sd, q))%rank < bodies(contact_line%pair_body(sd, q))%m, &
                            sd=1, 2)])
    end function pair_singular

  end subroutine harmonic_setup

  !> The groups of pairs joined through bodies in several pairs (the connected parts of the
  !! graph of bodies and pairs with more than one pair) and S = 2 K^-1 of each, on its rows.
  !! K = sum_a E_a' D_a Sigma_a D_a E_a is the stiffness of the group's bodies assembled on
  !! its rows: Sigma_a a body's stiffness on all its rows (`body_stiffness`: its projected
  !! inverse when floating), D_a = +1 on the rows where the body is side 1, -1 where it is
  !! side 2. With all rows active, the subproblems' forces move by -Sigma_a (the obstacles'
  !! change), so the imbalance d = lam_side1 - lam_side2 moves by -K (side 1's change) + K (side
  !! 2's change), and at delta = 0.5 the error map of S = 2 K^-1 is nilpotent (its square is
  !! zero), whatever the number of bodies and their contrast; two bodies: K = Sigma_1 +
  !! Sigma_2, the two-body operator (doc/method.md, "Several bodies and contact pairs").
  !! K is singular along the bodies' infinitely stiff directions: S is taken on their
  !! complement, as for a pair (`assembly_flex`). With friction the same S on all rows: S of
  !! the normal and of the tangential rows apart, each from the bodies' stiffnesses on those
  !! rows alone (`harmonic_by_kind` for two bodies), was singular on a stack of plates held
  !! sideways by friction alone, and no faster on the lap joint (9 outer iterations and 2439
  !! products against 8 and 3898).
  subroutine group_operators(self, contact_line, bodies, stiff, stiff_info, npairs, err)
    class(harmonic_operator_t), intent(inout) :: self
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(stiffness_t), intent(in) :: stiff(:)
    integer, intent(in) :: stiff_info(:), npairs(:)
    type(error_t), intent(inout) :: err
    integer, allocatable :: root(:), gof(:), rows(:), members(:)
    integer :: p, a, b, ng, g, i, m, info
    character(len=120) :: emsg
    m = contact_line%m
    do a = 1, size(bodies)
      if (.not. allocated(stiff(a)%k) .or. stiff_info(a) == 0) cycle
      write (emsg, '(a,i0,a,i0)') 'harmonic Robin operator: body ', a, &
        ': its stiffness on its contact rows failed, info = ', stiff_info(a)
      call err%set(ERR_NUMERICAL, emsg)
      return
    end do
    ! groups by union-find over the bodies of pairs with rows and a body in another pair
    allocate (root(size(bodies)), gof(size(bodies)))
    root = [(a, a=1, size(bodies))]
    do p = 1, contact_line%npair
      if (.not. in_group(p)) cycle
      a = find(contact_line%pair_body(1, p))
      b = find(contact_line%pair_body(2, p))
      if (a /= b) root(max(a, b)) = min(a, b)
    end do
    gof = 0
    ng = 0
    do p = 1, contact_line%npair
      if (.not. in_group(p)) cycle
      a = find(contact_line%pair_body(1, p))
      if (gof(a) == 0) then
        ng = ng + 1
        gof(a) = ng
      end if
    end do
    allocate (self%group(ng))
    do g = 1, ng
      ! the group's rows, ascending (its pairs' row ranges in pair order)
      allocate (rows(0))
      do p = 1, contact_line%npair
        if (.not. in_group(p)) cycle
        if (gof(find(contact_line%pair_body(1, p))) /= g) cycle
        rows = [rows, [(i, i=self%rows(1, p), self%rows(2, p))]]
      end do
      members = pack([(a, a=1, size(bodies))], [(gof(find(a)) == g .and. allocated(stiff(a)%k), a=1, size(bodies))])
      if (size(rows) > GROUP_DENSE_MAX) then
        ! too many rows for a dense K: K sparse, factored by CHOLMOD
        call sparse_group(self%group(g), rows, members, info)
      else
        call group_matrix(rows, members, self%group(g)%s, info)
      end if
      if (info /= 0) then
        write (emsg, '(a,i0,a,i0)') 'harmonic Robin operator: the assembled stiffness of a group of ', &
          size(members), ' bodies is not positive definite, info = ', info
        call err%set(ERR_NUMERICAL, emsg)
        return
      end if
      call move_alloc(rows, self%group(g)%rows)
    end do

  contains

    !> K of a large group as a sparse matrix (the upper triangles of its bodies' blocks,
    !! summed where bodies share rows) and its CHOLMOD factor (AMD ordering) in op%kf;
    !! info /= 0 when the factorization fails.
    subroutine sparse_group(op, sel, mem, info)
      type(group_op_t), intent(inout) :: op
      integer, intent(in) :: sel(:), mem(:)
      integer, intent(out) :: info
      integer, allocatable :: pos(:), loc(:), gr(:), ci(:), cj(:), ord(:)
      integer(ip), allocatable :: colptr(:), rowind(:)
      real(wp), allocatable :: cv(:), sg(:), val(:), blk(:, :)
      real(wp) :: rho
      integer :: n, ia, aa, ii, jj, ne, e, ml, c, nz, last_r
      type(error_t) :: ferr
      n = size(sel)
      allocate (pos(m))
      pos = 0
      pos(sel) = [(ii, ii=1, n)]
      ne = 0
      do ia = 1, size(mem)
        ne = ne + bodies(mem(ia))%m**2
      end do
      allocate (ci(ne), cj(ne), cv(ne))
      ne = 0
      do ia = 1, size(mem)
        aa = mem(ia)
        loc = pack([(ii, ii=1, bodies(aa)%m)], [(pos(slot_row(bodies(aa)%slots(ii), m)) > 0, ii=1, bodies(aa)%m)])
        ml = size(loc)
        gr = [(pos(slot_row(bodies(aa)%slots(loc(ii)), m)), ii=1, ml)]
        sg = [(merge(1.0_wp, -1.0_wp, slot_side(bodies(aa)%slots(loc(ii)), m) == 1), ii=1, ml)]
        ! a body infinitely stiff along some directions (a mortar master coarser than the
        ! slave): rho d d' added along each, rho = 1e6 |Sigma_a|_max, so that S = 2 K^-1 is
        ! small there, as the dense path's complement makes it zero (any positive definite
        ! S keeps the fixed point; this one is within about 1e-6 of that projection)
        blk = stiff(aa)%k(loc, loc)
        if (size(stiff(aa)%inf, 2) > 0) then
          rho = 1.0e6_wp*max(maxval(abs(stiff(aa)%k)), tiny(1.0_wp))
          do c = 1, size(stiff(aa)%inf, 2)
            do jj = 1, ml
              blk(:, jj) = blk(:, jj) + rho*stiff(aa)%inf(loc, c)*stiff(aa)%inf(loc(jj), c)
            end do
          end do
        end if
        do jj = 1, ml
          do ii = 1, ml
            if (gr(ii) > gr(jj)) cycle
            ne = ne + 1
            ci(ne) = gr(ii)
            cj(ne) = gr(jj)
            cv(ne) = sg(ii)*sg(jj)*blk(ii, jj)
          end do
        end do
      end do
      ! entries by column, then row
      ord = [(e, e=1, ne)]
      call merge_sort_by_keys(ord, reshape([(cj(e), ci(e), e=1, ne)], [2, ne]))
      ! merge duplicates into 0-based CSC
      allocate (colptr(n + 1), rowind(ne), val(ne))
      nz = 0
      colptr = 0
      c = 0
      last_r = 0
      do e = 1, ne
        if (cj(ord(e)) /= c) then        ! a new column (every column has its diagonal)
          c = cj(ord(e))
          last_r = 0
        end if
        if (ci(ord(e)) == last_r) then
          val(nz) = val(nz) + cv(ord(e))
        else
          nz = nz + 1
          rowind(nz) = int(ci(ord(e)) - 1, ip)
          val(nz) = cv(ord(e))
          last_r = ci(ord(e))
        end if
        colptr(c + 1) = int(nz, ip)
      end do
      call op%kf%factor(n, colptr, rowind(1:nz), val(1:nz), FACT_CHOLMOD, ORD_AMD, ferr)
      info = merge(1, 0, ferr%failed())
      op%sparse = .not. ferr%failed()
    end subroutine sparse_group

    !> Pair q has rows and a body in another pair.
    logical function in_group(q)
      integer, intent(in) :: q
      in_group = contact_line%pair_ptr(q + 1) > contact_line%pair_ptr(q) .and. &
                 .not. all(npairs(contact_line%pair_body(:, q)) == 1)
    end function in_group

    !> The root of body x's set.
    integer function find(x)
      integer, intent(in) :: x
      find = x
      do while (root(find) /= find)
        find = root(find)
      end do
    end function find

    !> S = 2 K^-1 on the rows `sel` (ascending) of the bodies `mem`: each body's stiffness
    !! on all its rows assembled with the side signs.
    subroutine group_matrix(sel, mem, op, info)
      integer, intent(in) :: sel(:), mem(:)
      type(dense_op_t), intent(out) :: op
      integer, intent(out) :: info
      real(wp), allocatable :: k(:, :), dirs(:, :), s(:, :), dk(:, :), dinf(:, :)
      integer, allocatable :: pos(:), loc(:), gr(:)
      real(wp), allocatable :: sg(:)
      integer :: n, ia, aa, ii, jj, c, nd, ml
      n = size(sel)
      allocate (pos(m), k(n, n), dirs(n, 0))
      pos = 0
      pos(sel) = [(ii, ii=1, n)]
      k = 0.0_wp
      info = 0
      do ia = 1, size(mem)
        aa = mem(ia)
        ! the body's rows among sel: local positions, group positions, side signs
        loc = pack([(ii, ii=1, bodies(aa)%m)], [(pos(slot_row(bodies(aa)%slots(ii), m)) > 0, ii=1, bodies(aa)%m)])
        ml = size(loc)
        if (ml == 0) cycle
        gr = [(pos(slot_row(bodies(aa)%slots(loc(ii)), m)), ii=1, ml)]
        sg = [(merge(1.0_wp, -1.0_wp, slot_side(bodies(aa)%slots(loc(ii)), m) == 1), ii=1, ml)]
        dk = stiff(aa)%k
        dinf = stiff(aa)%inf
        do jj = 1, ml
          do ii = 1, ml
            k(gr(ii), gr(jj)) = k(gr(ii), gr(jj)) + sg(ii)*sg(jj)*dk(ii, jj)
          end do
        end do
        nd = size(dirs, 2)
        if (size(dinf, 2) > 0) then
          dirs = reshape([dirs, [(0.0_wp, ii=1, n*size(dinf, 2))]], [n, nd + size(dinf, 2)])
          do c = 1, size(dinf, 2)
            dirs(gr, nd + c) = sg*dinf(:, c)
          end do
        end if
      end do
      if (size(dirs, 2) == 0) then
        ! S = 2 K^-1 by one Cholesky factor and its inverse
        call dpotrf('U', n, k, n, info)
        if (info == 0) call dpotri('U', n, k, n, info)
        if (info /= 0) return
        do jj = 1, n
          k(1:jj, jj) = 2.0_wp*k(1:jj, jj)
          k(jj, 1:jj - 1) = k(1:jj - 1, jj)
        end do
        call move_alloc(k, s)
      else
        call assembly_flex(k, dirs, s, info)
        if (info /= 0) return
      end if
      call dense_op_take(op, s)
    end subroutine group_matrix

  end subroutine group_operators

  !> corr(:, 1) = corr(:, 2) = S d, pair by pair and group by group.
  subroutine harmonic_apply(self, d, corr, count, it)
    class(harmonic_operator_t), intent(inout) :: self
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: corr(:, :)
    integer, intent(inout) :: count
    integer, intent(in) :: it                       !< outer iteration
    real(wp), allocatable :: y(:)
    integer :: p, c
    type(error_t) :: serr
    corr(:, 1) = 0.0_wp
    do p = 1, size(self%s)
      if (allocated(self%fac)) then
        if (allocated(self%fac(p)%l)) then
          if (it < self%fac(p)%form_at) then
            call factored_apply(self%fac(p), self%flexibility(self%fac(p)%stiff)%a, &
                                d(self%rows(1, p):self%rows(2, p)), corr(self%rows(1, p):self%rows(2, p), 1))
            count = count + 3     ! two products and two triangular solves
            cycle
          end if
          call form_factored(self%fac(p), self%flexibility(self%fac(p)%stiff)%a, self%s(p))
        end if
      end if
      if (self%s(p)%n == 0) cycle
      call self%s(p)%apply(d(self%rows(1, p):self%rows(2, p)), corr(self%rows(1, p):self%rows(2, p), 1))
    end do
    do c = 1, size(self%group)
      allocate (y(size(self%group(c)%rows)))
      if (self%group(c)%sparse) then
        ! S d = 2 K^-1 d by the factor's solves
        y = d(self%group(c)%rows)
        call self%group(c)%kf%solve(y, serr)
        y = 2.0_wp*y
        if (serr%failed()) then   ! the outer loop stops on it (exit 3), never on NaN
          if (.not. self%failure%failed()) call self%failure%set(ERR_NUMERICAL, &
            'the harmonic operator of a group of '//i2s(size(self%group(c)%rows))//' contact rows: '//serr%text())
          y = 0.0_wp
        end if
      else
        call self%group(c)%s%apply(d(self%group(c)%rows), y)
      end if
      corr(self%group(c)%rows, 1) = y
      deallocate (y)
    end do
    corr(:, 2) = corr(:, 1)
    count = count + 1
  end subroutine harmonic_apply

  !> The linearised outer map is nilpotent at delta = 0.5: the outer iteration is as exact
  !! as its subproblems, so they are solved tightly, scaled by the contrast of the bodies,
  !! down to what rounding lets the projected gradient reach (about sqrt(m) eps: asking for
  !! less only spins MPRGP up to inner_max_it) (doc/method.md, "Method as implemented", why 'harmonic').
  real(wp) function harmonic_tolerance(self, solver, it, m, progress, lmax) result(rtol_in)
    class(harmonic_operator_t), intent(in) :: self
    type(solver_cfg_t), intent(in) :: solver
    integer, intent(in) :: it, m
    real(wp), intent(in) :: progress, lmax(:)
    rtol_in = max(sqrt(real(max(m, 1), wp))*epsilon(1.0_wp), &
                  solver%inner_factor*solver%tol*minval(lmax)/max(maxval(lmax), tiny(1.0_wp)))
  end function harmonic_tolerance

  !> POWER_ITS power iterations (the inner tolerance uses the ratio of the two bodies'
  !! estimates, which the row-sum bound would distort).
  real(wp) function power_estimate(self, flexibility, flex, nmv) result(lmax)
    class(harmonic_operator_t), intent(in) :: self
    type(dense_op_t), intent(inout) :: flexibility
    real(wp), intent(in) :: flex(:, :)
    integer, intent(out) :: nmv
    lmax = lambda_max_estimate(flexibility, POWER_ITS, nmv)
  end function power_estimate

  !> Pi_a = Z R Z' on ker F_a only (Z its basis, R = Z' F_o Z floored, F_o the partners'
  !! flexibilities on a's rows): S annihilates ker F_a, so only the kernel needs pinning,
  !! and the body stays exact on range F_a. Without a kernel basis, F_o (doc/method.md, "Non-matching and curved contact surfaces:
  !! dual mortar").
  subroutine kernel_proximal(self, contact_line, bodies, a, p)
    class(harmonic_operator_t), intent(in) :: self
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: a
    real(wp), intent(out) :: p(:, :)
    integer :: o
    ! one partner on all of a's rows in their order (two bodies): its F as it is, no copy
    o = whole_partner(contact_line, bodies, a)
    if (o > 0) then
      call pin(bodies(o)%flex)
    else
      call pin(partner_flex(contact_line, bodies, a))
    end if

  contains

    subroutine pin(fo)
      real(wp), intent(in) :: fo(:, :)        !< the partners' flexibilities on a's rows
      real(wp), allocatable :: zf(:, :), zr(:, :), r(:, :)
      real(wp) :: floor
      integer :: i, k, m
      if (allocated(bodies(a)%rng)) then
        call range_proximal(bodies(a)%rng, fo, p)
        return
      end if
      if (.not. allocated(bodies(a)%kern)) then
        p = fo
        return
      end if
      m = bodies(a)%m
      k = size(bodies(a)%kern, 2)
      allocate (zf(k, m), zr(m, k), r(k, k))
      ! R = Z' F_o Z (k x k), F_o the partners' flexibilities, floored so that F_a + Pi_a is
      ! definite even if F_o is nearly singular on ker F_a
      call dgemm('T', 'N', k, m, m, 1.0_wp, bodies(a)%kern, m, fo, m, 0.0_wp, zf, k)
      call dgemm('N', 'N', k, k, m, 1.0_wp, zf, k, bodies(a)%kern, m, 0.0_wp, r, k)
      call symmetrize(r)
      floor = 0.0_wp
      do i = 1, m
        floor = max(floor, 1.0e-10_wp*fo(i, i))
      end do
      do i = 1, k
        r(i, i) = r(i, i) + floor
      end do
      call dgemm('N', 'N', m, k, k, 1.0_wp, bodies(a)%kern, m, r, k, 0.0_wp, zr, m)
      call dgemm('N', 'T', m, m, k, 1.0_wp, zr, m, bodies(a)%kern, m, 0.0_wp, p, m)
      call symmetrize(p)
    end subroutine pin

  end subroutine kernel_proximal

  !> The body whose F is the partners' flexibility of body a as it is (partner_flex without
  !! a copy): a's only pair's other body, when that pair holds all the rows of both in the
  !! same order; 0 otherwise.
  integer function whole_partner(contact_line, bodies, a) result(o)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    integer, intent(in) :: a
    integer :: q, n, ra(2), ro(2), b
    o = 0
    n = 0
    do q = 1, contact_line%npair
      if (all(contact_line%pair_body(:, q) /= a)) cycle
      n = n + 1
      b = sum(contact_line%pair_body(:, q)) - a
      ra = pair_positions(bodies(a), contact_line, q)
      ro = pair_positions(bodies(b), contact_line, q)
      if (n == 1 .and. b /= a .and. all(ra == [1, bodies(a)%m]) .and. all(ro == [1, bodies(b)%m]) .and. &
          bodies(b)%m == bodies(a)%m) o = b
    end do
    if (n /= 1) o = 0
  end function whole_partner

  !> kernel_proximal's Z R Z' from the range basis Q of F_a instead (Z Z' = I - Q Q', the
  !! kernel the larger part): P = (I - QQ') F_o (I - QQ') + floor (I - QQ'), as
  !! F_o - C Q' - Q C' - floor Q Q' + floor I with C = F_o Q - Q (Q' F_o Q)/2: O(m^2 r).
  subroutine range_proximal(q, fo, p)
    real(wp), intent(in) :: q(:, :)          !< (m, r) orthonormal basis of range F_a
    real(wp), intent(in) :: fo(:, :)         !< (m, m) the partners' flexibilities on a's rows
    real(wp), intent(out) :: p(:, :)         !< (m, m) the proximal term
    real(wp), allocatable :: c(:, :), b(:, :)
    real(wp) :: floor
    integer :: i, m, r
    m = size(q, 1)
    r = size(q, 2)
    floor = 0.0_wp
    do i = 1, m
      floor = max(floor, 1.0e-10_wp*fo(i, i))
    end do
    p = fo
    do i = 1, m
      p(i, i) = p(i, i) + floor
    end do
    if (r > 0) then
      allocate (c(m, r), b(r, r))
      call dgemm('N', 'N', m, r, m, 1.0_wp, fo, m, q, m, 0.0_wp, c, m)
      call dgemm('T', 'N', r, r, m, 1.0_wp, q, m, c, m, 0.0_wp, b, r)
      call dgemm('N', 'N', m, r, r, -0.5_wp, q, m, b, r, 1.0_wp, c, m)
      call dgemm('N', 'T', m, m, r, -1.0_wp, c, m, q, m, 1.0_wp, p, m)
      call dgemm('N', 'T', m, m, r, -1.0_wp, q, m, c, m, 1.0_wp, p, m)
      call dgemm('N', 'T', m, m, r, -floor, q, m, q, m, 1.0_wp, p, m)
    end if
    call symmetrize(p)
  end subroutine range_proximal

  !> S = 2 F_1 (F_1 + F_2)^-1 F_2 = 2 (F_1^-1 + F_2^-1)^-1 (symmetric positive definite).
  !> S = 2 (F1^-1 + F2^-1)^-1 for the normal rows and for the tangential rows of a pair apart
  !! (S block diagonal by row kind, each block from the blocks of F1 and F2 on those rows).
  !! Where every node slips, the tangential forces sit at their bounds and only the normal rows
  !! are constrained: the exact harmonic operator of that state is the normal block's, and the
  !! whole F's block on the normal rows is not (the paper's scene with mu = 0.3: 52 outer
  !! iterations with the whole F, 10 with this; half stick, half slip (Cattaneo-Mindlin): 14
  !! and 15; all stick: 25 and 22). Any symmetric positive definite S keeps the fixed point.
  subroutine harmonic_by_kind(f1, f2, tangential, s, info)
    real(wp), intent(in) :: f1(:, :), f2(:, :)
    logical, intent(in) :: tangential(:)      ! the rows of the slip (the others: of the normal gap)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: sk(:, :)
    integer, allocatable :: idx(:)
    integer :: k, i, m, kinfo(0:1)
    integer(c_long) :: ntiles
    m = size(f1, 1)
    allocate (s(m, m))
    s = 0.0_wp
    kinfo = 0
    ! the two kinds' blocks (0: normal, 1: tangential) on the two threads (disjoint parts of s)
    !$omp parallel do num_threads(body_threads()) schedule(static, 1) private(k, idx, sk, ntiles) if (m > 256)
    do k = 0, 1
      idx = pack([(i, i=1, m)], tangential .eqv. (k == 1))
      if (size(idx) == 0) cycle
      ! as tiles: the thread of the smaller kind (the normal rows, a third of the tangential
      ! ones) helps with the larger once it is done
      call tiles_begin()
      call harmonic_lean(f1(idx, idx), f2(idx, idx), sk, kinfo(k))
      ntiles = tiles_end()
      if (kinfo(k) == 0) s(idx, idx) = sk
    end do
    !$omp end parallel do
    info = kinfo(0)
    if (info == 0) info = kinfo(1)
  end subroutine harmonic_by_kind

  !> S = 2 F_s (F_1 + F_2)^-1 F_o = 2 F_s - 2 Y'Y with Y = L^-1 F_s, L L' = F_1 + F_2 and F_s
  !! the one of smaller trace (the stiffer body: the subtracted term is then the smaller one):
  !! one Cholesky factor, one triangular solve and one symmetric rank-k product, and symmetric
  !! by construction.
  subroutine harmonic_lean(f1, f2, s, info)
    real(wp), intent(in) :: f1(:, :), f2(:, :)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    type(pair_factor_t) :: fac
    call harmonic_factor(f1, f2, fac, info)
    if (info /= 0) return
    if (fac%stiff == 1) then
      call lean_matrix(fac, f1, s)
    else
      call lean_matrix(fac, f2, s)
    end if
  end subroutine harmonic_lean

  !> The Cholesky factor of F_1 + F_2 (fac%l) and the side of the smaller trace (fac%stiff:
  !! 1 or 2); fac%form_at from the size: forming S (a triangular solve with m right-hand sides
  !! and a symmetric rank-m product, 2 m^3 flops at the speed of matrix products) takes about
  !! as long as m/16 factored applications (two symmetric products and two triangular solves,
  !! 6 m^2 flops at the speed of the memory), so a run of up to max(8, m/16) outer iterations
  !! never forms it, and a longer one spends at most twice the least it could.
  subroutine harmonic_factor(f1, f2, fac, info)
    real(wp), intent(in) :: f1(:, :), f2(:, :)
    type(pair_factor_t), intent(out) :: fac
    integer, intent(out) :: info
    integer :: m, i
    m = size(f1, 1)
    allocate (fac%l(m, m))
    fac%l = f1 + f2
    call dpotrf('L', m, fac%l, m, info)
    if (info /= 0) then
      deallocate (fac%l)
      return
    end if
    fac%stiff = 1
    if (sum([(f2(i, i), i=1, m)]) < sum([(f1(i, i), i=1, m)])) fac%stiff = 2
    fac%form_at = max(8, m/16) + 1
  end subroutine harmonic_factor

  !> y = S d = 2 F_s d - 2 F_s (L L')^-1 F_s d.
  subroutine factored_apply(fac, fs, d, y)
    type(pair_factor_t), intent(in) :: fac
    real(wp), intent(in) :: fs(:, :)               !< F_s
    real(wp), intent(in) :: d(:)
    real(wp), intent(out) :: y(:)
    real(wp), allocatable :: w(:), z(:)
    integer :: m
    m = size(d)
    allocate (w(m), z(m))
    call dsymv('U', m, 1.0_wp, fs, m, d, 1, 0.0_wp, w, 1)
    z = w
    call dtrsv('L', 'N', 'N', m, fac%l, m, z, 1)
    call dtrsv('L', 'T', 'N', m, fac%l, m, z, 1)
    call dsymv('U', m, 1.0_wp, fs, m, z, 1, 0.0_wp, y, 1)
    y = 2.0_wp*(w - y)
  end subroutine factored_apply

  !> S = 2 F_s - 2 Y'Y with Y = L^-1 F_s into s; the factor released.
  subroutine form_factored(fac, fs, s)
    type(pair_factor_t), intent(inout) :: fac
    real(wp), intent(in) :: fs(:, :)               !< F_s
    type(dense_op_t), intent(inout) :: s
    real(wp), allocatable :: sm(:, :)
    call lean_matrix(fac, fs, sm)
    deallocate (fac%l)
    call dense_op_take(s, sm)
  end subroutine form_factored

  !> s = 2 F_s - 2 Y'Y, Y = L^-1 F_s (both triangles).
  subroutine lean_matrix(fac, fs, s)
    type(pair_factor_t), intent(in) :: fac
    real(wp), intent(in) :: fs(:, :)               !< F_s
    real(wp), allocatable, intent(out) :: s(:, :)
    real(wp), allocatable :: y(:, :)
    integer :: m, i
    m = size(fs, 1)
    y = fs
    s = 2.0_wp*fs
    call dtrsm('L', 'L', 'N', 'N', m, m, 1.0_wp, fac%l, m, y, m)
    call dsyrk('L', 'T', m, m, -2.0_wp, y, m, 1.0_wp, s, m)
    do i = 1, m - 1
      s(i, i + 1:m) = s(i + 1:m, i)
    end do
  end subroutine lean_matrix


  !> The harmonic operator of a pair with a floating body: S = 2 (Sigma_A + Sigma_B)^-1,
  !! Sigma = F^-1 for a supported body's block and the projected inverse Q (`projected_inverse`)
  !! for a floating one's (doc/method.md, "Bodies held only by contact"). One floating f, the
  !! other o supported: S = 2 (I + F_o Q_f)^-1 F_o (no inverse of F_o). Both floating:
  !! S = 2 (Q_A + Q_B)^-1. info /= 0: a factorization failed.
  subroutine harmonic_floating(blk, s, info)
    type(block_t), intent(in) :: blk(2)             !< the pair's blocks of its two bodies
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: q(:, :, :), a(:, :)
    integer, allocatable :: ipiv(:)
    integer :: m, f, o, i
    m = size(blk(1)%f, 1)
    allocate (q(m, m, 2), s(m, m), a(m, m), ipiv(m))
    do f = 1, 2
      if (blk(f)%nrig == 0) cycle
      call projected_inverse(blk(f)%f, blk(f)%g, q(:, :, f), info)
      if (info /= 0) return
    end do
    if (blk(1)%nrig > 0 .and. blk(2)%nrig > 0) then
      a = q(:, :, 1) + q(:, :, 2)
      call symmetrize(a)
      s = 0.0_wp
      do i = 1, m
        s(i, i) = 2.0_wp
      end do
      call dposv('U', m, m, a, m, s, m, info)
    else
      f = merge(1, 2, blk(1)%nrig > 0)
      o = 3 - f
      ! (I + F_o Q_f) X = F_o, S = 2 X
      a = mm('N', 'N', blk(o)%f, q(:, :, f))
      do i = 1, m
        a(i, i) = a(i, i) + 1.0_wp
      end do
      s = 2.0_wp*blk(o)%f
      call dgesv(m, m, a, m, ipiv, s, m, info)
    end if
    call symmetrize(s)
  end subroutine harmonic_floating

  !> The harmonic operator of a pair of two bodies (in no other pair) with a floating body
  !! and a singular F (a mortar master coarser than the slave): S = 2 (Sigma_A + Sigma_B)^-1
  !! of their stiffnesses (`body_stiffness`, `parallel_flex`), no inverse of a singular F.
  subroutine harmonic_singular(blk, s, info)
    type(block_t), intent(in) :: blk(2)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    type(stiffness_t) :: st(2)
    integer :: side, infos(2)
    ! the two bodies' eigendecompositions on the threads
    !$omp parallel do num_threads(min(2, body_threads())) schedule(static, 1) private(side)
    do side = 1, 2
      if (blk(side)%nrig > 0) then
        call body_stiffness(blk(side)%f, blk(side)%g, st(side)%k, st(side)%inf, infos(side))
      else
        call body_stiffness(blk(side)%f, reshape([real(wp) ::], [0, size(blk(side)%f, 1)]), st(side)%k, &
                            st(side)%inf, infos(side))
      end if
    end do
    !$omp end parallel do
    info = maxval(abs(infos))
    if (info /= 0) return
    call parallel_flex(st(1)%k, st(1)%inf, st(2)%k, st(2)%inf, s, info)
  end subroutine harmonic_singular

  !> A body's stiffness on its contact rows, Sigma = Z (Z' F Z)^+ Z' (Z a basis of the
  !! forces its equilibrium rows g see as balanced, Z = I without rows: for a nonsingular F
  !! of a supported body, F^-1; of a floating one, its projected inverse), and the
  !! directions where Z' F Z is singular, along which the body is infinitely stiff (the
  !! multipliers a mortar master coarser than the slave cannot feel).
  subroutine body_stiffness(f, g, k, inf, info)
    real(wp), intent(in) :: f(:, :)                 !< (m, m) F
    real(wp), intent(in) :: g(:, :)                 !< (r, m) equilibrium rows (r = 0: none)
    real(wp), allocatable, intent(out) :: k(:, :)   !< (m, m) Sigma
    real(wp), allocatable, intent(out) :: inf(:, :) !< (m, *) the infinitely stiff directions
    integer, intent(out) :: info
    real(wp), allocatable :: z(:, :), c(:, :), ev(:), work(:), y(:, :), w(:, :)
    integer, allocatable :: iwork(:), keep(:)
    real(wp) :: cut
    integer :: m, nz, i, j, lwork, liwork
    logical :: ok
    m = size(f, 1)
    info = 0
    call cholesky_stiffness(f, g, k, ok)
    if (ok) then
      allocate (inf(m, 0))
      return
    end if
    if (size(g, 1) == 0) then
      ! no equilibrium rows: Z = I, so Z' F Z is F and the eigenvectors are y
      nz = m
      c = 0.5_wp*(f + transpose(f))
    else
      z = complement(transpose(g), m)
      nz = size(z, 2)
      y = mm('N', 'N', f, z)
      c = mm('T', 'N', z, y)
      call symmetrize(c)
    end if
    allocate (ev(nz), work(1), iwork(1), k(m, m))
    k = 0.0_wp
    info = 0
    if (nz == 0) then
      allocate (inf(m, 0))
      return
    end if
    ! all eigenpairs by divide and conquer (a sixth of dsyev's time at nz = 2000)
    call dsyevd('V', 'U', nz, c, nz, ev, work, -1, iwork, -1, info)
    lwork = max(1 + 6*nz + 2*nz*nz, int(work(1)))
    liwork = max(3 + 5*nz, iwork(1))
    deallocate (work, iwork)
    allocate (work(lwork), iwork(liwork))
    call dsyevd('V', 'U', nz, c, nz, ev, work, lwork, iwork, liwork, info)
    if (info /= 0) return
    if (allocated(z)) then
      y = mm('N', 'N', z, c)   ! the eigenvectors in the rows' space
    else
      call move_alloc(c, y)
    end if
    cut = 1.0e-10_wp*maxval(ev)
    inf = y(:, pack([(i, i=1, nz)], ev <= cut))
    ! Sigma = W W' with W the kept eigenvectors y_i scaled by 1/sqrt(ev_i): its upper triangle
    ! by one rank-k update, then mirrored (exactly symmetric)
    keep = pack([(i, i=1, nz)], ev > cut)
    allocate (w(m, size(keep)))
    do j = 1, size(keep)
      w(:, j) = y(:, keep(j))/sqrt(ev(keep(j)))
    end do
    if (size(keep) > 0) call dsyrk('U', 'N', m, size(keep), 1.0_wp, w, m, 0.0_wp, k, m)
    do j = 1, m - 1
      k(j + 1:m, j) = k(j, j + 1:m)
    end do
  end subroutine body_stiffness

  !> Sigma of a body whose F is well conditioned (ok; else Sigma is not set): with its
  !! equilibrium rows g, the projected inverse F^-1 - F^-1 g' (g F^-1 g')^-1 g F^-1, which
  !! equals Z (Z' F Z)^-1 Z' (eigenvalues of Z' F Z lie within F's: none is infinitely stiff),
  !! from one Cholesky factorization of F (a few times cheaper than the eigendecomposition).
  subroutine cholesky_stiffness(f, g, k, ok)
    real(wp), intent(in) :: f(:, :)                 !< (m, m) F
    real(wp), intent(in) :: g(:, :)                 !< (r, m) equilibrium rows (r = 0: none)
    real(wp), allocatable, intent(out) :: k(:, :)   !< (m, m) Sigma
    logical, intent(out) :: ok
    real(wp), allocatable :: h(:, :), work(:)
    integer, allocatable :: iwork(:)
    real(wp) :: rcond
    integer :: m, r, j, info
    ok = .false.
    m = size(f, 1)
    r = size(g, 1)
    if (m == 0) return
    h = f
    call dpotrf('U', m, h, m, info)
    if (info /= 0) return
    allocate (work(3*m), iwork(m))
    call dpocon('U', m, h, m, maxval(sum(abs(f), dim=1)), rcond, work, iwork, info)
    if (info /= 0 .or. .not. rcond > RCOND_CHOLESKY) return
    call dpotri('U', m, h, m, info)
    if (info /= 0) return
    do j = 1, m - 1
      h(j + 1:m, j) = h(j, j + 1:m)
    end do
    if (r > 0) then
      call project_rows_out(h, g, info)
      if (info /= 0) return
    end if
    call move_alloc(h, k)
    ok = .true.
  end subroutine cholesky_stiffness

  !> S = 2 (Sigma_A + Sigma_B)^-1 of two stiffnesses on the same rows, zero along their
  !! infinitely stiff directions: S = 2 V (V' (Sigma_A + Sigma_B) V)^-1 V', V a basis of the
  !! complement of those directions (the subproblems' proximal term pins them instead, as for
  !! a supported coarse master). info /= 0: V' (Sigma_A + Sigma_B) V is not definite.
  subroutine parallel_flex(ka, infa, kb, infb, s, info)
    real(wp), intent(in) :: ka(:, :), infa(:, :), kb(:, :), infb(:, :)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: dirs(:, :)
    integer :: m
    m = size(ka, 1)
    allocate (dirs(m, size(infa, 2) + size(infb, 2)))
    dirs(:, 1:size(infa, 2)) = infa
    dirs(:, size(infa, 2) + 1:) = infb
    call assembly_flex(ka + kb, dirs, s, info)
  end subroutine parallel_flex

  !> S = 2 V (V' K V)^-1 V' of an assembled stiffness K, V a basis of the complement of the
  !! infinitely stiff directions `dirs` (V = I without them: S = 2 K^-1). info /= 0:
  !! V' K V is not definite.
  subroutine assembly_flex(k, dirs, s, info)
    real(wp), intent(in) :: k(:, :), dirs(:, :)
    real(wp), allocatable, intent(out) :: s(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: v(:, :), t(:, :), x(:, :)
    integer :: m, nv
    m = size(k, 1)
    allocate (s(m, m))
    v = complement(dirs, m)
    nv = size(v, 2)
    s = 0.0_wp
    info = 0
    if (nv == 0) return
    t = k
    x = mm('N', 'N', t, v)
    t = mm('T', 'N', v, x)
    call symmetrize(t)
    x = transpose(v)
    call dposv('U', nv, m, t, nv, x, nv, info)
    if (info /= 0) return
    s = 2.0_wp*mm('N', 'N', v, x)
    call symmetrize(s)
  end subroutine assembly_flex

  !> C = op(A) op(B) (op: 'N' as it is, 'T' transposed) by BLAS: the dense blocks of a
  !! contact line are products of order m^3, where the intrinsic matmul is several times
  !! slower than dgemm.
  function mm(ta, tb, a, b) result(c)
    character(len=1), intent(in) :: ta, tb
    real(wp), intent(in) :: a(:, :), b(:, :)
    real(wp), allocatable :: c(:, :)
    integer :: m, n, k
    m = merge(size(a, 2), size(a, 1), ta == 'T')
    k = merge(size(a, 1), size(a, 2), ta == 'T')
    n = merge(size(b, 1), size(b, 2), tb == 'T')
    allocate (c(m, n))
    if (m == 0 .or. n == 0) return
    if (k == 0) then
      c = 0.0_wp
      return
    end if
    call dgemm(ta, tb, m, n, k, 1.0_wp, a, size(a, 1), b, size(b, 1), 0.0_wp, c, m)
  end function mm

  !> An orthonormal basis of the orthogonal complement of the columns of a (m x n): the
  !! left singular vectors beyond its numerical rank (1e-10 of its largest singular value).
  function complement(a, m) result(z)
    real(wp), intent(in) :: a(:, :)
    integer, intent(in) :: m
    real(wp), allocatable :: z(:, :)
    real(wp), allocatable :: u(:, :), sv(:), vt(:, :), work(:), ac(:, :)
    integer :: n, r, lwork, info
    n = size(a, 2)
    if (n == 0) then
      allocate (z(m, m))
      z = 0.0_wp
      do r = 1, m
        z(r, r) = 1.0_wp
      end do
      return
    end if
    ac = a
    allocate (u(m, m), sv(min(m, n)), vt(1, 1), work(1))
    call dgesvd('A', 'N', m, n, ac, m, sv, u, m, vt, 1, work, -1, info)
    lwork = max(1, int(work(1)))
    deallocate (work)
    allocate (work(lwork))
    call dgesvd('A', 'N', m, n, ac, m, sv, u, m, vt, 1, work, lwork, info)
    r = count(sv > 1.0e-10_wp*maxval(sv))
    if (info /= 0) r = 0
    z = u(:, r + 1:m)
  end function complement

  !> The projected inverse Q = F^-1 - F^-1 G' (G F^-1 G')^-1 G F^-1 of a floating body's
  !! block F with its equilibrium rows G (full row rank).
  subroutine projected_inverse(f, g, q, info)
    real(wp), intent(in) :: f(:, :)
    real(wp), intent(in) :: g(:, :)
    real(wp), intent(out) :: q(:, :)
    integer, intent(out) :: info
    real(wp), allocatable :: h(:, :)
    integer :: m, i
    m = size(f, 1)
    allocate (h(m, m))
    h = f
    q = 0.0_wp
    do i = 1, m
      q(i, i) = 1.0_wp
    end do
    call dposv('U', m, m, h, m, q, m, info)
    if (info /= 0) return
    call project_rows_out(q, g, info)
  end subroutine projected_inverse

  !> finv <- F^-1 - y (G F^-1 G')^-1 y' with y = F^-1 G' (finv holds F^-1 on entry, G has
  !! full row rank), symmetrized; info /= 0: G F^-1 G' is not positive definite.
  subroutine project_rows_out(finv, g, info)
    real(wp), intent(inout) :: finv(:, :)           !< (m, m) F^-1 in, the projected inverse out
    real(wp), intent(in) :: g(:, :)                 !< (r, m) G
    integer, intent(out) :: info
    real(wp), allocatable :: y(:, :), gg(:, :), t(:, :)
    integer :: m, r
    m = size(finv, 1)
    r = size(g, 1)
    y = matmul(finv, transpose(g))
    gg = matmul(g, y)
    t = transpose(y)
    call dposv('U', r, m, gg, r, t, r, info)
    if (info /= 0) return
    finv = finv - matmul(y, t)
    call symmetrize(finv)
  end subroutine project_rows_out

end module robin_operators
