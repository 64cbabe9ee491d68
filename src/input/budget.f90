!> What a deck costs before anything is allocated: the memory estimate of a run (meshes,
!! assembled matrices, Cholesky factors, interface matrices) and the checks that it fits
!! the machine and the 32-bit indices of the sparse matrices; and loads whose stresses stay
!! within double precision. A deck that cannot fit is
!! bad input (exit 1) with the estimate and the limit in the message: a run must not
!! allocate until the kernel's OOM killer ends it.
!!
!! The factor estimate is calibrated on measured runs (README, "Performance"): nested
!! dissection orderings (metis, nd, amd) of a structured 2D body of n DOFs fill about
!! 8 n log2(n) entries; the banded factorization and the natural order fill n times the
!! half-bandwidth. Counts are computed in double precision, so no integer overflows.
module budget
  use kinds, only: wp
  use config, only: deck_t, body_cfg_t, factor_cfg_t, ELEM_Q1, FACTOR_BANDED, ORDER_NATURAL
  use strings, only: i2s, sci, fmt_real
  implicit none (type, external)
  private

  real(wp), parameter :: MIB = 1048576.0_wp
  real(wp), parameter :: INDEX_MAX = 2147483647.0_wp   ! largest 32-bit index
  real(wp), parameter :: BASE_MB = 64.0_wp             ! the program, libraries and small arrays

  public :: body_memory_mb, run_memory_mb, check_budget, check_load_range

contains

  !> Memory of one body [MiB]: mesh, assembled matrix and load, factor, work vectors.
  !! `nnz_matrix` returns the matrix entries (both triangles) and `nnz_factor` the factor's.
  real(wp) function body_memory_mb(b, fc, nnz_matrix, nnz_factor) result(mb)
    type(body_cfg_t), intent(in) :: b        !< the body
    type(factor_cfg_t), intent(in) :: fc     !< its factorization
    real(wp), intent(out) :: nnz_matrix      !< stored matrix entries
    real(wp), intent(out) :: nnz_factor      !< factor entries
    real(wp) :: nodes, cells, n, half_band
    nodes = (real(b%nx, wp) + 1.0_wp)*(real(b%ny, wp) + 1.0_wp)
    cells = real(b%nx, wp)*real(b%ny, wp)
    n = 2.0_wp*nodes
    nnz_matrix = 18.0_wp*n                    ! 9 neighbour nodes x 2 components per row
    if (fc%factorization == FACTOR_BANDED) then
      ! reverse Cuthill-McKee: the half-bandwidth follows the shorter side
      half_band = 2.0_wp*(real(min(b%nx, b%ny), wp) + 2.0_wp)
      nnz_factor = n*half_band
    else if (fc%ordering == ORDER_NATURAL) then
      ! nodes numbered along x, and the interface DOFs (at most both components of the
      ! longer side) ordered last fill their rows
      half_band = 2.0_wp*(real(b%nx, wp) + 2.0_wp)
      nnz_factor = n*half_band + n*2.0_wp*(real(max(b%nx, b%ny), wp) + 1.0_wp)
    else
      nnz_factor = 8.0_wp*n*log(max(n, 2.0_wp))/log(2.0_wp)
    end if
    mb = (16.0_wp*nodes + merge(16.0_wp, 24.0_wp, b%element == ELEM_Q1)*cells &   ! mesh
          + 12.0_wp*nnz_matrix + 64.0_wp*n &                                      ! matrix, vectors
          + 8.0_wp*nnz_factor + 4.0_wp*nnz_factor/16.0_wp)/MIB                    ! factor values, indices
  end function body_memory_mb

  !> Memory of the whole run [MiB] (both bodies, interface matrices, a base).
  real(wp) function run_memory_mb(d) result(mb)
    type(deck_t), intent(in) :: d   !< the deck
    real(wp) :: nm, nf, m
    integer :: a
    mb = BASE_MB
    m = 0.0_wp
    do a = 1, 2
      mb = mb + body_memory_mb(d%body(a), d%solver%factor, nm, nf)
      m = max(m, real(max(d%body(a)%nx, d%body(a)%ny), wp) + 1.0_wp)
    end do
    mb = mb + 10.0_wp*8.0_wp*m*m/MIB          ! F_1, F_2, their operators, S, the bound's copies
  end function run_memory_mb

  !> Refuse a deck that cannot run here: a body whose matrix or factor overflows 32-bit
  !! indices, or a run whose estimate exceeds `limit_mb` (0: no limit known). ok = .false.
  !! with msg naming the deck, the estimate and the limit.
  subroutine check_budget(d, limit_mb, ok, msg)
    type(deck_t), intent(in) :: d                       !< the deck
    real(wp), intent(in) :: limit_mb                    !< memory this process may use [MiB]
    logical, intent(out) :: ok                          !< the run fits
    character(len=:), allocatable, intent(out) :: msg   !< why not
    real(wp) :: nm, nf, mb, est
    integer :: a
    ok = .true.
    msg = ''
    do a = 1, 2
      mb = body_memory_mb(d%body(a), d%solver%factor, nm, nf)
      if (nm > INDEX_MAX .or. nf > INDEX_MAX) then
        ok = .false.
        msg = 'deck '//trim(d%source)//': body '//i2s(a)//' (nx = '//i2s(d%body(a)%nx)//', ny = '// &
              i2s(d%body(a)%ny)//') needs about '//fmt_real(nm/1.0e9_wp, '(f0.2)')//'e9 matrix and '//fmt_real(nf/1.0e9_wp, '(f0.2)')// &
              'e9 factor entries, beyond the 2^31 (2.1e9) that the 32-bit indices of this build hold; '// &
              'use fewer cells'
        return
      end if
    end do
    est = run_memory_mb(d)
    if (limit_mb > 0.0_wp .and. est > limit_mb) then
      ok = .false.
      msg = 'deck '//trim(d%source)//': the run needs about '//fmt_real(est/1024.0_wp, '(f0.2)')// &
            ' GiB (body 1: '//fmt_real(body_memory_mb(d%body(1), d%solver%factor, nm, nf)/1024.0_wp, '(f0.2)')// &
            ' GiB, body 2: '//fmt_real(body_memory_mb(d%body(2), d%solver%factor, nm, nf)/1024.0_wp, '(f0.2)')// &
            ' GiB: meshes, matrices and Cholesky factors) but this process may use only '// &
            fmt_real(limit_mb/1024.0_wp, '(f0.2)')//' GiB (available memory, cgroup or ulimit -v); '// &
            'use fewer cells or a machine with more memory'
    end if
  end subroutine check_budget

  !> Loads within double precision: a traction or prescribed displacement whose stresses
  !! would overflow (1e308 Pa) is refused, with a margin of 1e6 for the products of
  !! assembly and stress recovery. ok = .false. with msg naming the group and the value.
  subroutine check_load_range(d, ok, msg)
    type(deck_t), intent(in) :: d                       !< the deck
    logical, intent(out) :: ok                          !< the loads are representable
    character(len=:), allocatable, intent(out) :: msg   !< why not
    real(wp), parameter :: MARGIN = 1.0e6_wp
    real(wp) :: ext, t, h, u, cap
    integer :: i, a, s
    ok = .true.
    msg = ''
    ext = 1.0_wp
    do a = 1, 2
      ext = max(ext, abs(d%body(a)%x0) + d%body(a)%width, abs(d%body(a)%y0) + d%body(a)%height)
    end do
    ! every product below stays finite (no overflow trap in the checked build): ext is a
    ! coordinate extent, far below huge/MARGIN for any deck that passed its own checks
    cap = huge(1.0_wp)/(ext*MARGIN)
    do i = 1, d%ntraction
      t = maxval(abs(d%traction(i)%t0))
      if (maxval(abs(d%traction(i)%t1)) < cap/ext) then
        t = t + maxval(abs(d%traction(i)%t1))*ext
      else
        t = huge(1.0_wp)
      end if
      if (.not. t < cap) then
        ok = .false.
        msg = 'deck '//trim(d%source)//': &traction '//i2s(i)//' (body '//i2s(d%traction(i)%body)// &
              ') reaches '//sci(t)//' [stress]: its stresses would overflow double precision; '// &
              'rescale the units (e.g. &scene units=''mm-N-MPa'')'
        return
      end if
    end do
    do a = 1, 2
      h = min(d%body(a)%width/real(d%body(a)%nx, wp), d%body(a)%height/real(d%body(a)%ny, wp))
      do s = 1, 4
        u = maxval(abs(d%body(a)%u_side(:, s)))
        if (.not. u > 0.0_wp) cycle   ! (no short-circuit in Fortran: log(0) must not be evaluated)
        if (.not. log(u) + log(d%body(a)%young) - log(h) + log(MARGIN) < log(huge(1.0_wp))) then
          ok = .false.
          msg = 'deck '//trim(d%source)//': the &displacement of body '//i2s(a)//' ('//sci(u)// &
                ' [length]) with young = '//sci(d%body(a)%young)//' gives stresses beyond double '// &
                'precision; rescale the units'
          return
        end if
      end do
    end do
  end subroutine check_load_range

end module budget
