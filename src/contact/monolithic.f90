!> The monolithic reference: the discrete contact problem of all pairs in one piece,
!! min 1/2 lam'(sum_a E_a' F_a E_a) lam - lam'(sum_a E_a' b_a - g0), lam >= 0, by MPRGP
!! (SMALBE-M with the floating bodies' equilibrium rows); E_a picks body a's rows. Two
!! bodies in one pair: the dense F_1 + F_2; more pairs: the sum assembled sparse (pairs
!! couple only through a shared body). Every converged Robin run must match it. With
!! friction the tangential rows' forces lie in boxes (Tresca); Coulomb's boxes follow the
!! normal forces, by repeated box solves until the normal forces settle.
module monolithic
  use kinds, only: wp
  use config, only: solver_cfg_t, METHOD_MONOLITHIC
  use linop, only: linop_t, dense_op_t, dense_op_init, csc_op_t, csc_op_init
  use lapack, only: dsyrk, dpotrf, dtrsm, dtrsv
  use clock, only: wtime
  use mprgp, only: mprgp_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_STOPPED, &
                   mprgp_status_name, QP_AUTO, QP_MPRGP, QP_NEWTON
  use smalbe, only: smalbe_solve, smalbe_solve_in, smalbe_stats_t
  use tangent_discs, only: friction_set
  use strings, only: i2s
  use sorting, only: sort_ints
  use contact_interface, only: interface_t, slot_row, slot_side, has_friction, row_bounds, disc_rows, DIR_NORMAL
  use config, only: FRICTION_COULOMB, INNER_MPRGP, INNER_ACTIVE_SET
  use condense, only: body_condensed_t
  use signals, only: stop_iface
  use contact_types, only: contact_result_t, alloc_result, STATUS_CONVERGED, STATUS_MAX_OUTER, &
                           STATUS_FAILED, STATUS_INTERRUPTED
  use contact_common, only: interface_residual, all_finite, gather, scatter, body_threads
  use equality_rows, only: equality_t, equality_init, equality_add_penalty, stacked_rows, equality_force_scaled
  implicit none (type, external)
  private

  !> H + rho G'G as an operator: H sparse, G (r, m) by rows, its nonzeros only (a floating
  !! body's rows touch its own pairs' rows, and after the orthonormalization those of the
  !! bodies it is chained to: a small block per chain, not r x m).
  type, extends(linop_t) :: penalized_op_t
    type(csc_op_t) :: h
    real(wp) :: rho = 0.0_wp
    integer :: r = 0                            !< rows of G
    integer, allocatable :: rowptr(:), col(:)   !< row i's nonzeros: col(rowptr(i):rowptr(i+1)-1)
    real(wp), allocatable :: val(:)             !< their values
  contains
    procedure :: apply => penalized_apply
  end type penalized_op_t

  integer, parameter :: COULOMB_MAX_FIXED = 500   !< box solves of the monolithic Coulomb fixed point
  !> The Coulomb fixed point has settled at the rounding level of its box solves when this
  !! many solves have not halved its smallest relative change of the slip bounds, which is
  !! at most STALL_CHANGE (sqrt(eps): the least a QP solve resolves of an ill-conditioned H)
  integer, parameter :: STALL_FIXED = 10
  real(wp), parameter :: STALL_CHANGE = 1.0e-8_wp

  public :: solve_monolithic, assemble_hessian

contains

  !> The monolithic solve; res holds the solution, its residuals and one history entry.
  subroutine solve_monolithic(solver, contact_line, bodies, res, stop_requested)
    type(solver_cfg_t), intent(in) :: solver             !< solver settings
    type(interface_t), intent(in) :: contact_line        !< contact rows of all pairs
    type(body_condensed_t), intent(in) :: bodies(:)      !< condensed bodies
    type(contact_result_t), intent(out) :: res           !< solution and status
    procedure(stop_iface), optional :: stop_requested    !< true when the run must stop (signal)
    class(linop_t), allocatable :: hessian
    type(mprgp_t) :: inner_solver
    type(mprgp_stats_t) :: inner
    type(smalbe_stats_t) :: outer
    type(equality_t) :: equality
    real(wp), allocatable :: c(:), lb(:), ub(:), lam(:), rows(:, :), rhs(:), eq_mult(:), bs(:, :), wa(:), lfac(:, :), ub_new(:)
    integer :: m, a, r, nrig, info, fixed, nfix, nmv
    real(wp) :: t0, lmax, change, change_best
    integer :: fixed_best
    logical :: friction
    logical, allocatable :: tangent(:)

    m = contact_line%m
    t0 = wtime()
    res%method = METHOD_MONOLITHIC
    call alloc_result(res, m, 1, size(bodies))
    allocate (c(m), lb(m), lam(m), bs(m, 2))
    ! c = sum_a E_a' b_a - g0: each row has one body on each side
    bs = 0.0_wp
    do a = 1, size(bodies)
      call scatter(bodies(a)%b, bodies(a)%slots, bs)
    end do
    c = bs(:, 1) + bs(:, 2) - contact_line%g0
    lb = 0.0_wp
    lam = 0.0_wp
    inner_solver%opts%rtol = solver%monolithic_rtol
    ! monolithic_rtol relative to |c|, or the rounding level of H lam where that is out of reach
    inner_solver%opts%rounding_floor = .true.
    inner_solver%opts%max_it = solver%inner_max_it
    select case (solver%inner_solver)
    case (INNER_MPRGP)
      inner_solver%opts%method = QP_MPRGP
    case (INNER_ACTIVE_SET)
      inner_solver%opts%method = QP_NEWTON
    case default
      inner_solver%opts%method = QP_AUTO
    end select
    if (present(stop_requested)) inner_solver%opts%stop => stop_requested
    nrig = sum(bodies(:)%nrig)
    if (nrig > 0 .and. m > 0) call stacked_rows(bodies, m, rows, rhs)
    if (contact_line%npair == 1) then
      allocate (dense_op_t :: hessian)
      select type (hessian)
      type is (dense_op_t)
        call dense_op_init(hessian, bodies(1)%flex + bodies(2)%flex)
        ! floating bodies: their equilibrium rows, stacked
        if (nrig > 0 .and. m > 0) then
          inner_solver%opts%lambda_max = maxval(sum(abs(hessian%a), dim=1))
          call equality_init(equality, rows, rhs, inner_solver%opts%lambda_max)
          call equality_add_penalty(equality, hessian, inner_solver%opts%lambda_max)
        end if
      end select
    else
      ! several pairs: H sparse; the floating bodies' rows orthonormalized (a chain of
      ! floating bodies has G G' like a 1D Laplacian, whose conditioning would slow SMALBE's
      ! multiplier updates as the chain grows), the penalty applied as rho G'(G x)
      allocate (penalized_op_t :: hessian)
      select type (hessian)
      type is (penalized_op_t)
        call assemble_hessian(contact_line, bodies, hessian%h, lmax)
        hessian%n = m
        inner_solver%opts%lambda_max = lmax
        if (nrig > 0 .and. m > 0) then
          call orthonormal_rows(rows, rhs, lfac, info)
          if (info /= 0) then
            res%status = STATUS_FAILED
            res%message = 'monolithic: the floating bodies'' equilibrium rows are linearly dependent'
            return
          end if
          call equality_init(equality, rows, rhs, lmax)
          hessian%rho = equality%rho
          call sparse_rows(equality%g, hessian)
          inner_solver%opts%lambda_max = lmax + equality%rho*equality%gg
        end if
      end select
    end if
    if (equality%r > 0) then
      allocate (eq_mult(equality%r))
      eq_mult = 0.0_wp
    end if
    ! friction: the boxes of the tangential rows; Coulomb repeats the box solve with the
    ! boxes of the last normal forces (warm-started) until they change by less than
    ! monolithic_rtol relative, at most COULOMB_MAX_FIXED times
    friction = has_friction(contact_line)
    nfix = 1
    if (friction .and. equality%r > 0) call equality_force_scaled(equality)
    if (friction) then
      allocate (ub(m), ub_new(m))
      call row_bounds(contact_line, lam, lb, ub, start=.true.)
      tangent = contact_line%dir > DIR_NORMAL
      if (any(contact_line%pair_friction == FRICTION_COULOMB)) nfix = COULOMB_MAX_FIXED
    end if
    nmv = 0
    change_best = huge(1.0_wp)
    fixed_best = 0
    do fixed = 1, nfix
    if (m > 0) then
      if (equality%r > 0) then
        inner_solver%opts%eq_m = equality%m0
        inner_solver%opts%eq_feas = equality%feas
        inner_solver%opts%eq_feas_x = equality%feas_x
        if (friction) then
          ! the box of the tangential forces, or in space their discs
          call smalbe_solve_in(inner_solver, hessian, c, equality%g, equality%e, equality%rho, &
                               friction_set(lb, ub, disc_rows(contact_line)), lam, eq_mult, outer)
        else
          call smalbe_solve(inner_solver, hessian, c, equality%g, equality%e, equality%rho, lb, lam, eq_mult, outer)
        end if
        inner = outer%inner
        inner%n_matvec = outer%n_matvec
        res%eq_updates = res%eq_updates + outer%updates
        ! multipliers of the orthonormalized rows L^-1 G back to those of G: eq_mult = L^-T eq_mult~
        if (allocated(lfac)) call dtrsv('L', 'T', 'N', size(eq_mult), lfac, size(eq_mult), eq_mult, 1)
        r = 0
        do a = 1, size(bodies)
          if (bodies(a)%nrig == 0) cycle
          res%rigid(1:bodies(a)%nrig, a) = -eq_mult(r + 1:r + bodies(a)%nrig)
          r = r + bodies(a)%nrig
        end do
      else
        if (friction) then
          call inner_solver%solve_in(hessian, c, friction_set(lb, ub, disc_rows(contact_line)), lam)
        else
          call inner_solver%solve(hessian, c, lb, lam)
        end if
        inner = inner_solver%stats
        ! the Coulomb fixed point's next box solves: the Newton method at once if this one needed it
        if (inner%switched) inner_solver%opts%method = QP_NEWTON
      end if
      nmv = nmv + inner%n_matvec
      res%inner = nmv
      if (inner%status == MPRGP_STOPPED) then
        res%status = STATUS_INTERRUPTED
        res%message = 'monolithic MPRGP stopped by a signal after '//i2s(inner%n_cg + inner%n_exp + inner%n_prop)// &
                      ' steps (no checkpoint: the monolithic solve is one step)'
      else if (inner%status /= MPRGP_CONVERGED) then
        res%status = merge(STATUS_MAX_OUTER, STATUS_FAILED, inner%status == MPRGP_MAX_IT)
        res%message = 'monolithic MPRGP: '//trim(mprgp_status_name(inner%status))//': '//trim(inner%message)
      else
        res%status = STATUS_CONVERGED
      end if
    else
      res%status = STATUS_CONVERGED
    end if
    if (friction .and. equality%r > 0 .and. res%status == STATUS_MAX_OUTER) res%message = trim(res%message)// &
      '; with friction: a body held along a direction by friction alone cannot be held when its load there '// &
      'exceeds mu times the normal force its contact carries (no static equilibrium: it slides)'
    if (nfix == 1 .or. res%status /= STATUS_CONVERGED) exit
    call row_bounds(contact_line, lam, lb, ub_new)
    ! the first solve had no Coulomb bound (row_bounds' start): nothing to compare with
    change = huge(1.0_wp)
    if (fixed > 1) change = norm2(pack(ub_new - ub, tangent))/max(norm2(pack(ub_new, tangent)), tiny(1.0_wp))
    if (change <= solver%monolithic_rtol) exit
    ! the changes stop shrinking below the rounding level of the box solves' forces (an
    ! ill-conditioned H): settled when STALL_FIXED solves have not halved the smallest change
    if (change < 0.5_wp*change_best) then
      change_best = change
      fixed_best = fixed
    else if (fixed - fixed_best >= STALL_FIXED .and. change_best <= STALL_CHANGE) then
      exit
    end if
    if (fixed == nfix) then
      res%status = STATUS_MAX_OUTER
      write (res%message, '(a,i0,a,es10.3)') 'monolithic Coulomb: the slip bounds still changed after ', nfix, &
        ' box solves, by ', change
      exit
    end if
    call row_bounds(contact_line, lam, lb, ub)
    end do
    res%outer = min(fixed, nfix)
    res%lam = lam
    res%lam_body(:, 1) = lam
    res%lam_body(:, 2) = lam
    res%obstacle = 0.0_wp
    do a = 1, size(bodies)
      ! B_a u_a with the rigid part B_a R_a alpha_a = G_a' alpha_a of a floating body
      wa = bodies(a)%b - matmul(bodies(a)%flex, gather(res%lam_body, bodies(a)%slots))
      if (bodies(a)%nrig > 0) wa = wa + matmul(res%rigid(1:bodies(a)%nrig, a), bodies(a)%rg)
      call scatter(wa, bodies(a)%slots, res%w)
    end do
    call interface_residual(contact_line, bodies, res)
    res%criterion = res%residual
    res%nhist = 1
    res%h_criterion(1) = res%criterion
    res%h_residual(1) = res%residual
    res%h_inner(1) = res%inner
    res%h_active(1) = res%active
    res%h_wall(1) = wtime() - t0
    if (res%status == STATUS_CONVERGED .and. .not. all_finite(lam)) then
      res%status = STATUS_FAILED
      res%message = 'monolithic solution has non-finite values'
    end if
  end subroutine solve_monolithic

  !> H = sum_a E_a' F_a E_a in compressed sparse columns (both triangles, rows in the order
  !! the blocks list them, or ascending when `sorted`) and its row-sum bound lmax of
  !! lambda_max: each row belongs to the two bodies of its pair, so column j gathers their
  !! two blocks.
  subroutine assemble_hessian(contact_line, bodies, op, lmax, sorted)
    type(interface_t), intent(in) :: contact_line
    type(body_condensed_t), intent(in) :: bodies(:)
    type(csc_op_t), intent(out) :: op
    real(wp), intent(out) :: lmax
    logical, intent(in), optional :: sorted          !< rows ascending in each column (CHOLMOD's input)
    integer, allocatable :: owner(:, :), colptr(:), rowind(:), mark(:), list(:)
    real(wp), allocatable :: val(:), acc(:), rowsum(:)
    integer :: m, a, s, i, j, k, n, row, slot, p
    logical :: sort_rows
    m = contact_line%m
    sort_rows = .false.
    if (present(sorted)) sort_rows = sorted
    ! owner(:, j): (body, position in its rows) of each side of row j
    allocate (owner(4, m))
    do a = 1, size(bodies)
      do i = 1, bodies(a)%m
        slot = bodies(a)%slots(i)
        row = slot_row(slot, m)
        s = slot_side(slot, m)
        owner(2*s - 1:2*s, row) = [a, i]
      end do
    end do
    allocate (colptr(m + 1), rowsum(m))
    ! the columns on the threads, each with its own work arrays: pass 1 counts a column's
    ! entries, pass 2 sums and stores them (every column the same sums in the same order)
    !$omp parallel num_threads(body_threads()) private(j, k, n, p, mark, acc, list) if (m > 256)
    allocate (mark(m), acc(m), list(m))
    mark = 0
    acc = 0.0_wp
    !$omp do schedule(static)
    do j = 1, m
      n = 0
      call visit(j, .false., n, mark, acc, list)
      colptr(j + 1) = n
      do k = 1, n
        mark(list(k)) = 0
      end do
    end do
    !$omp end do
    !$omp single
    colptr(1) = 0
    do j = 1, m
      colptr(j + 1) = colptr(j) + colptr(j + 1)
    end do
    allocate (rowind(colptr(m + 1)), val(colptr(m + 1)))
    !$omp end single
    !$omp do schedule(static)
    do j = 1, m
      n = 0
      call visit(j, .true., n, mark, acc, list)
      if (sort_rows) call sort_ints(list(1:n))
      rowsum(j) = 0.0_wp
      p = colptr(j)
      do k = 1, n
        p = p + 1
        rowind(p) = list(k) - 1
        val(p) = acc(list(k))
        rowsum(j) = rowsum(j) + abs(acc(list(k)))
        acc(list(k)) = 0.0_wp
        mark(list(k)) = 0
      end do
    end do
    !$omp end do
    deallocate (mark, acc, list)
    !$omp end parallel
    lmax = 0.0_wp
    if (m > 0) lmax = maxval(rowsum)
    call csc_op_init(op, m, colptr, rowind, val)

  contains

    !> Column jj's entries from the blocks of its two bodies: rows into lst(1:nn) (mk marks
    !! them), values summed into ac (when add).
    subroutine visit(jj, add, nn, mk, ac, lst)
      integer, intent(in) :: jj
      logical, intent(in) :: add
      integer, intent(inout) :: nn, mk(:), lst(:)
      real(wp), intent(inout) :: ac(:)
      integer :: side, b, col, ii, sl, r
      do side = 1, 2
        b = owner(2*side - 1, jj)
        col = owner(2*side, jj)
        do ii = 1, bodies(b)%m
          sl = bodies(b)%slots(ii)
          r = slot_row(sl, m)
          if (mk(r) == 0) then
            nn = nn + 1
            lst(nn) = r
            mk(r) = 1
          end if
          if (add) ac(r) = ac(r) + bodies(b)%flex(ii, col)
        end do
      end do
    end subroutine visit

  end subroutine assemble_hessian

  !> y = H x + rho G'(G x).
  subroutine penalized_apply(self, x, y)
    class(penalized_op_t), intent(inout) :: self
    real(wp), intent(in) :: x(:)
    real(wp), intent(out) :: y(:)
    real(wp) :: gx
    integer :: i, k
    call self%h%apply(x, y)
    do i = 1, self%r
      gx = 0.0_wp
      do k = self%rowptr(i), self%rowptr(i + 1) - 1
        gx = gx + self%val(k)*x(self%col(k))
      end do
      gx = self%rho*gx
      do k = self%rowptr(i), self%rowptr(i + 1) - 1
        y(self%col(k)) = y(self%col(k)) + self%val(k)*gx
      end do
    end do
  end subroutine penalized_apply

  !> The nonzeros of the rows of g (r, m), row by row (columns ascending), into op.
  subroutine sparse_rows(g, op)
    real(wp), intent(in) :: g(:, :)
    type(penalized_op_t), intent(inout) :: op
    integer, allocatable :: next(:)
    integer :: i, j
    op%r = size(g, 1)
    allocate (op%rowptr(op%r + 1), next(op%r))
    next = 0
    do j = 1, size(g, 2)
      do i = 1, op%r
        if (g(i, j) /= 0.0_wp) next(i) = next(i) + 1
      end do
    end do
    op%rowptr(1) = 1
    do i = 1, op%r
      op%rowptr(i + 1) = op%rowptr(i) + next(i)
    end do
    allocate (op%col(op%rowptr(op%r + 1) - 1), op%val(op%rowptr(op%r + 1) - 1))
    next = op%rowptr(1:op%r)
    do j = 1, size(g, 2)
      do i = 1, op%r
        if (g(i, j) == 0.0_wp) cycle
        op%col(next(i)) = j
        op%val(next(i)) = g(i, j)
        next(i) = next(i) + 1
      end do
    end do
  end subroutine sparse_rows

  !> G <- L^-1 G, e <- L^-1 e with G G' = L L' (Cholesky): rows with G G' = I, the same
  !! constraint. info /= 0: G G' is not definite (dependent rows).
  subroutine orthonormal_rows(g, e, l, info)
    real(wp), intent(inout) :: g(:, :), e(:)
    real(wp), allocatable, intent(out) :: l(:, :)
    integer, intent(out) :: info
    integer :: r, i
    r = size(g, 1)
    allocate (l(r, r))
    call dsyrk('L', 'N', r, size(g, 2), 1.0_wp, g, r, 0.0_wp, l, r)
    call dpotrf('L', r, l, r, info)
    if (info /= 0) return
    do i = 1, r - 1
      l(i, i + 1:) = 0.0_wp
    end do
    call dtrsm('L', 'L', 'N', 'N', r, size(g, 2), 1.0_wp, l, r, g, r)
    call dtrsv('L', 'N', 'N', r, l, r, e, 1)
  end subroutine orthonormal_rows

end module monolithic
