!> The monolithic reference: the discrete contact problem in one piece,
!! min 1/2 lam'(F_1 + F_2) lam - lam'(b_1 + b_2 - g0), lam >= 0, by MPRGP (SMALBE-M with
!! the floating bodies' equilibrium rows). Every converged Robin run must match it.
module monolithic
  use kinds, only: wp
  use config, only: solver_cfg_t
  use linop, only: dense_op_t, dense_op_init
  use clock, only: wtime
  use mprgp, only: mprgp_t, mprgp_stats_t, MPRGP_CONVERGED, MPRGP_MAX_IT, MPRGP_STOPPED, &
                   mprgp_status_name
  use smalbe, only: smalbe_solve, smalbe_stats_t
  use strings, only: itoa
  use condense, only: interface_t, body_condensed_t
  use contact_types, only: contact_result_t, stop_iface, alloc_result, STATUS_CONVERGED, STATUS_MAX_OUTER, &
                           STATUS_FAILED, STATUS_INTERRUPTED
  use contact_common, only: interface_residual, all_finite
  use equality_rows, only: equality_t, equality_init, equality_add_penalty, stacked_rows
  implicit none (type, external)
  private

  public :: solve_monolithic

contains

  !> The monolithic solve; res holds the solution, its residuals and one history entry.
  subroutine solve_monolithic(solver, contact_line, bodies, res, stop_requested)
    type(solver_cfg_t), intent(in) :: solver             !< solver settings
    type(interface_t), intent(in) :: contact_line        !< contact line
    type(body_condensed_t), intent(in) :: bodies(2)      !< condensed bodies
    type(contact_result_t), intent(out) :: res           !< solution and status
    procedure(stop_iface), optional :: stop_requested    !< true when the run must stop (signal)
    type(dense_op_t) :: hessian
    type(mprgp_t) :: inner_solver
    type(mprgp_stats_t) :: inner
    type(smalbe_stats_t) :: outer
    type(equality_t) :: equality
    real(wp), allocatable :: c(:), lb(:), lam(:), rows(:, :), rhs(:), mu(:)
    integer :: m, a, r1
    real(wp) :: t0

    m = contact_line%m
    t0 = wtime()
    res%method = 'monolithic'
    call alloc_result(res, m, 1)
    allocate (c(m), lb(m), lam(m))
    call dense_op_init(hessian, bodies(1)%flex + bodies(2)%flex)
    c = bodies(1)%b + bodies(2)%b - contact_line%g0
    lb = 0.0_wp
    lam = 0.0_wp
    inner_solver%opts%rtol = solver%monolithic_rtol
    inner_solver%opts%max_it = solver%inner_max_it
    if (present(stop_requested)) inner_solver%opts%stop => stop_requested
    ! floating bodies: both bodies' equilibrium rows, stacked
    r1 = bodies(1)%nrig
    if (r1 + bodies(2)%nrig > 0 .and. m > 0) then
      call stacked_rows(bodies, rows, rhs)
      allocate (mu(size(rhs)))
      inner_solver%opts%lambda_max = maxval(sum(abs(hessian%a), dim=1))
      call equality_init(equality, rows, rhs, inner_solver%opts%lambda_max)
      call equality_add_penalty(equality, hessian, inner_solver%opts%lambda_max)
      mu = 0.0_wp
    end if
    if (m > 0) then
      if (equality%r > 0) then
        inner_solver%opts%eq_m = equality%m0
        inner_solver%opts%eq_feas = equality%feas
        inner_solver%opts%eq_feas_x = equality%feas_x
        call smalbe_solve(inner_solver, hessian, c, equality%g, equality%e, equality%rho, lb, lam, mu, outer)
        inner = outer%inner
        inner%n_matvec = outer%n_matvec
        res%eq_updates = outer%updates
        if (r1 > 0) res%rigid(1:r1, 1) = -mu(1:r1)
        if (bodies(2)%nrig > 0) res%rigid(1:bodies(2)%nrig, 2) = -mu(r1 + 1:)
      else
        call inner_solver%solve(hessian, c, lb, lam)
        inner = inner_solver%stats
      end if
      res%inner = inner%n_matvec
      if (inner%status == MPRGP_STOPPED) then
        res%status = STATUS_INTERRUPTED
        res%message = 'monolithic MPRGP stopped by a signal after '//trim(itoa(inner%n_cg + inner%n_exp + inner%n_prop))// &
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
    res%outer = 1
    res%lam = lam
    do a = 1, 2
      res%lam_body(:, a) = lam
      ! B_a u_a with the rigid part B_a R_a alpha_a = G_a' alpha_a of a floating body
      res%w(:, a) = bodies(a)%b - matmul(bodies(a)%flex, lam)
      if (bodies(a)%nrig > 0) res%w(:, a) = res%w(:, a) + matmul(res%rigid(1:bodies(a)%nrig, a), bodies(a)%rg)
      res%obstacle(:, a) = 0.0_wp
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

end module monolithic
