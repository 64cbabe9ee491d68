!> The equality rows G lam = e of bodies held only by contact (module floating), as the
!! QP solvers see them: each floating body's equilibrium, with the SMALBE settings that go
!! with the Hessian H they are added to (A = H + rho G'G).
module equality_rows
  use kinds, only: wp
  use lapack, only: dgemm, dsyev
  use linop, only: dense_op_t
  use condense, only: body_condensed_t
  use contact_interface, only: slot_row
  use nonneg_lsq, only: sparse_cols_t
  implicit none (type, external)
  private

  real(wp), parameter :: RHO_FACTOR = 10.0_wp       !< SMALBE penalty rho = RHO_FACTOR lambda_max(H) / |G G'|
  real(wp), parameter :: FEAS_RTOL = 1.0e-12_wp     !< equilibrium: |G lam - e| <= FEAS_RTOL |e| (monolithic)

  !> Equality rows G lam = e and the SMALBE settings for a Hessian H.
  type, public :: equality_t
    integer :: r = 0                          !< rows (0: no equality, plain MPRGP)
    real(wp), allocatable :: g(:, :)          !< (r, m) G [-]
    real(wp), allocatable :: e(:)             !< (r) e [force]
    real(wp) :: rho = 0.0_wp                  !< penalty [length/force]
    real(wp) :: gg = 0.0_wp                   !< lambda_max(G G') [-]
    real(wp) :: m0 = 0.0_wp                   !< SMALBE's initial M [length/force]
    real(wp) :: feas = 0.0_wp                 !< |G lam - e| that counts as equilibrium [force]
    real(wp) :: feas_x = 0.0_wp               !< e = 0: per unit of |lam| instead (FEAS_RTOL |G|) [-]
  end type equality_t

  public :: equality_init, equality_add_penalty, gram_eigenvalues, stacked_rows, stacked_columns, equality_force_scaled

contains

  !> The equality rows G lam = e for a QP whose Hessian H has its largest eigenvalue below
  !! lmax: the penalty rho = RHO_FACTOR lmax / lambda_max(G G') (A = H + rho G'G stays within
  !! (1 + RHO_FACTOR) lmax, and a multiplier update reduces |G lam - e| by about
  !! 1 / (1 + RHO_FACTOR)), SMALBE's initial M = lmax / sqrt(lambda_max(G G')) (a gradient per
  !! unit of force imbalance), and the equilibrium tolerance FEAS_RTOL |e|, or FEAS_RTOL |G| |lam|
  !! when e = 0 (nothing loads the body along its free motions, a deformation presses it
  !! into the contact: the contact forces' size is the scale then).
  subroutine equality_init(q, g, e, lmax)
    type(equality_t), intent(out) :: q      !< the rows and their settings
    real(wp), intent(in) :: g(:, :)         !< (r, m) G
    real(wp), intent(in) :: e(:)            !< (r) e
    real(wp), intent(in) :: lmax            !< bound of lambda_max(H)
    q%r = size(g, 1)
    q%g = g
    q%e = e
    q%gg = max(maxval(gram_eigenvalues(g)), tiny(1.0_wp))
    q%rho = RHO_FACTOR*lmax/q%gg
    q%m0 = lmax/sqrt(q%gg)
    q%feas = FEAS_RTOL*max(norm2(e), tiny(1.0_wp))
    if (all(e == 0.0_wp)) q%feas_x = FEAS_RTOL*sqrt(q%gg)
  end subroutine equality_init

  !> The equilibrium tolerance counted in the contact forces as well, FEAS_RTOL |G| |lam| when
  !! that is larger than FEAS_RTOL |e|: with friction a floating body's tangential forces
  !! can be large and cancel, its load small against them, and |G lam - e| cannot be brought
  !! below the rounding of the forces.
  subroutine equality_force_scaled(q)
    type(equality_t), intent(inout) :: q
    q%feas_x = max(q%feas_x, FEAS_RTOL*sqrt(q%gg))
  end subroutine equality_force_scaled

  !> Add the penalty rho G'G to the dense Hessian and its bound to lmax.
  subroutine equality_add_penalty(q, hessian, lmax)
    type(equality_t), intent(in) :: q              !< the rows (equality_init)
    type(dense_op_t), intent(inout) :: hessian     !< H in, H + rho G'G out
    real(wp), intent(inout) :: lmax                !< bound of lambda_max(H) in, of the sum out
    integer :: m
    m = size(q%g, 2)
    call dgemm('T', 'N', m, m, q%r, q%rho, q%g, q%r, q%g, q%r, 1.0_wp, hessian%a, m)
    lmax = lmax + q%rho*q%gg
  end subroutine equality_add_penalty

  !> The floating bodies' equilibrium rows stacked in body order over the m contact rows of
  !! all pairs: g (sum r_a, m), each body's G_a on the rows it takes part in, e (sum r_a).
  subroutine stacked_rows(bodies, m, g, e)
    type(body_condensed_t), intent(in) :: bodies(:)      !< condensed bodies
    integer, intent(in) :: m                             !< contact rows of all pairs
    real(wp), allocatable, intent(out) :: g(:, :)        !< stacked G_a
    real(wp), allocatable, intent(out) :: e(:)           !< stacked e_a
    type(sparse_cols_t) :: gs
    integer :: k, l
    call stacked_columns(bodies, m, gs, e)
    allocate (g(gs%nrow, m))
    g = 0.0_wp
    do k = 1, m
      do l = gs%ptr(k), gs%ptr(k + 1) - 1
        g(gs%row(l), k) = gs%val(l)
      end do
    end do
  end subroutine stacked_rows

  !> The same rows by their nonzeros: a column per contact row, its entries in the rigid
  !! rows of the (at most two) floating bodies it touches (a few per column, whatever the
  !! number of bodies).
  subroutine stacked_columns(bodies, m, g, e)
    type(body_condensed_t), intent(in) :: bodies(:)      !< condensed bodies
    integer, intent(in) :: m                             !< contact rows of all pairs
    type(sparse_cols_t), intent(out) :: g                !< stacked G_a, (rigid rows, m)
    real(wp), allocatable, intent(out) :: e(:)           !< stacked e_a
    integer, allocatable :: ti(:), tj(:)
    real(wp), allocatable :: tv(:)
    integer :: a, r, i, q, nz
    r = 0
    nz = 0
    do a = 1, size(bodies)
      r = r + bodies(a)%nrig
      if (bodies(a)%nrig > 0) nz = nz + bodies(a)%nrig*bodies(a)%m
    end do
    allocate (e(r), ti(nz), tj(nz), tv(nz))
    r = 0
    nz = 0
    do a = 1, size(bodies)
      if (bodies(a)%nrig == 0) cycle
      do i = 1, bodies(a)%m
        do q = 1, bodies(a)%nrig
          nz = nz + 1
          ti(nz) = r + q
          tj(nz) = slot_row(bodies(a)%slots(i), m)
          tv(nz) = bodies(a)%rg(q, i)
        end do
      end do
      e(r + 1:r + bodies(a)%nrig) = bodies(a)%re
      r = r + bodies(a)%nrig
    end do
    call g%from_triplets(r, m, ti, tj, tv)
  end subroutine stacked_columns

  !> The eigenvalues of G G' (r <= 6 rows), ascending; if LAPACK fails, 0 and, last, the
  !! row-sum bound of the largest (what the penalty and the error bound's projection can
  !! still use safely).
  function gram_eigenvalues(g) result(ev)
    real(wp), intent(in) :: g(:, :)   !< (r, m) rows
    real(wp) :: ev(size(g, 1))
    real(wp) :: work(64), gg(size(g, 1), size(g, 1))
    integer :: r, info
    r = size(g, 1)
    gg = matmul(g, transpose(g))
    call dsyev('N', 'U', r, gg, r, ev, work, size(work), info)
    if (info /= 0) then
      gg = matmul(g, transpose(g))
      ev = 0.0_wp
      ev(r) = maxval(sum(abs(gg), dim=1))
    end if
  end function gram_eigenvalues

end module equality_rows
