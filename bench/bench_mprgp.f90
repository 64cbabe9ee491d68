!> Benchmark of the MPRGP solver (prints, asserts nothing).
!!
!! 1. The 1D obstacle problem -u'' = -15 on (0,1), u(0) = u(1) = 0, u >= -1, by
!!    finite differences: A = tridiag(-1,2,-1)*(n+1)^2 (scaled form, sparse CSC),
!!    b = -15, l = -1, start x = 0. Same solution as the unscaled form
!!    tridiag(-1,2,-1), b = -15 h^2, and the same iteration counts up to rounding
!!    (MPRGP and its stopping test |gP| <= rtol |b| are invariant under A, b -> cA, cb).
!! 2. A dense contact-like problem: A = inverse of tridiag(-1,2,-1)*(m+1)^2 (the
!!    discrete Green's function, a smooth dense "flexibility" like the condensed
!!    F_a of the contact solver), b_i = sin(3 pi x_i), l = 0 (about a third active).
!!
!! Columns: size, rtol, products with A (power iterations included), CG /
!! expansion / proportioning steps, wall time per solve (module clock, averaged
!! over repeated solves), final |gP|/|b| (at the true gradient), status.
program bench_mprgp
  use kinds, only: wp
  use linop, only: csc_op_t, dense_op_t, dense_op_init, linop_t
  use mprgp, only: mprgp_t, mprgp_status_name
  use clock, only: wtime
  use testing, only: obstacle_problem
  implicit none (type, external)

  write (*, '(a)') 'MPRGP benchmark (Gamma = 1, alpha_bar = 1.9/lambda_max from 20 power iterations)'
  call table('1D obstacle: -u'''' = -15, u >= -1, A = tridiag(-1,2,-1)*(n+1)^2 (CSC), x0 = 0', &
             [100, 1000, 5000], .false.)
  write (*, '(a)') ''
  call table('dense Green''s function (inverse FD Laplacian), b = sin(3 pi x), l = 0, dsymv, x0 = 0', &
             [500, 1000, 2000], .true.)

contains

  !> One table: its title, the header, a row for each rtol and size, of the dense problem
  !! or of the obstacle problem.
  subroutine table(title, sizes, dense)
    character(len=*), intent(in) :: title
    integer, intent(in) :: sizes(:)
    logical, intent(in) :: dense
    real(wp), parameter :: rtols(2) = [1.0e-4_wp, 1.0e-8_wp]
    integer :: i, j
    write (*, '(a)') title
    write (*, '(a)') '     n      rtol   A-products      cg     exp    prop    time/solve [s]   |gP|/|b|   status'
    do j = 1, size(rtols)
      do i = 1, size(sizes)
        if (dense) then
          call run_dense(sizes(i), rtols(j))
        else
          call run_obstacle(sizes(i), rtols(j))
        end if
      end do
    end do
  end subroutine table

  subroutine run_obstacle(n, rtol)
    integer, intent(in) :: n
    real(wp), intent(in) :: rtol
    type(csc_op_t) :: op
    real(wp), allocatable :: b(:), l(:)
    call obstacle_problem(n, op, b, l, 1.0_wp)
    call timed(op, b, l, n, rtol)
  end subroutine run_obstacle

  subroutine run_dense(m, rtol)
    integer, intent(in) :: m
    real(wp), intent(in) :: rtol
    type(dense_op_t) :: op
    real(wp), allocatable :: a(:,:), b(:), l(:)
    real(wp) :: h, xi, xj
    integer :: i, j
    allocate (a(m, m), b(m), l(m))
    h = 1.0_wp / (m + 1)
    ! (tridiag(-1,2,-1)/h^2)^-1 = h * G, G_ij = x_min (1 - x_max)
    do j = 1, m
      xj = j * h
      do i = 1, m
        xi = i * h
        a(i, j) = h * min(xi, xj) * (1.0_wp - max(xi, xj))
      end do
      b(j) = sin(3.0_wp * acos(-1.0_wp) * xj)
    end do
    l = 0.0_wp
    call dense_op_init(op, a)
    deallocate (a)
    call timed(op, b, l, m, rtol)
  end subroutine run_dense

  subroutine timed(op, b, l, n, rtol)
    class(linop_t), intent(inout) :: op
    real(wp), intent(in) :: b(:), l(:)
    integer, intent(in) :: n
    real(wp), intent(in) :: rtol
    type(mprgp_t) :: solver
    real(wp), allocatable :: x(:)
    integer :: reps
    real(wp) :: t0, elapsed
    allocate (x(n))
    solver%opts%rtol = rtol
    solver%opts%max_it = 1000000
    x = 0.0_wp
    call solver%solve(op, b, l, x)   ! warm-up, not timed
    reps = 0
    t0 = wtime()
    do
      x = 0.0_wp
      call solver%solve(op, b, l, x)
      reps = reps + 1
      elapsed = wtime() - t0
      if (elapsed >= 0.5_wp .or. reps >= 1000) exit
    end do
    associate (st => solver%stats)
      write (*, '(i6,es10.1,i13,3i8,es18.3,es11.2,3x,a)') n, rtol, st%n_matvec, st%n_cg, st%n_exp, &
        st%n_prop, elapsed / reps, st%gp_norm / st%b_norm, mprgp_status_name(st%status)
    end associate
  end subroutine timed

end program bench_mprgp
