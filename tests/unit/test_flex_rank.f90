!> The numerical rank of a body's flexibility F_a = B X B' (condense `flex_from_x`): the
!! rank the pivoted Cholesky factor (LAPACK dpstrf, pivots below 1e-10 max diag) finds on the
!! same F_a, whichever way flex_from_x decides it, and the kernel basis of a singular F_a.
!! Rows of two entries each (not a selection of DOFs), X symmetric positive definite:
!! full rank; two equal rows (rank m - 1); a pair of rows that differ by 1e-4 (F_a's smallest
!! eigenvalue near 1e-8 of its largest: full rank for the pivoted factor, but too close
!! for a condition estimate to tell) and 1e-7 (near 1e-14: rank m - 1); a row on no free
!! DOF (F_a's row and column zero). The near-kernel of a singular F_a: a row on no free DOF
!! and two rows 1e-4 apart (an eigenvalue near 1e-8 of the largest, below NEAR_KERNEL = 1e-6):
!! the kernel basis takes that direction too (rank m - 2, one more than the pivoted factor's
!! m - 1), |F z| <= 1e-6 |F| on it; the same pair without the empty row keeps full rank and no
!! kernel (a nonsingular F_a gets none, however small its smallest eigenvalue).
program test_flex_rank
  use kinds, only: wp
  use condense, only: body_condensed_t, flex_from_x
  use lapack, only: dpstrf
  use testing, only: report, report_le, test_summary
  implicit none (type, external)
  integer, parameter :: M = 60

  call case('full rank', 0.0_wp, .false., .false., M)
  call case('two equal rows', 0.0_wp, .true., .false., M - 1)
  call case('two rows 1e-4 apart', 1.0e-4_wp, .true., .false., M)
  call case('two rows 1e-7 apart', 1.0e-7_wp, .true., .false., M - 1)
  call case('a row on no free DOF', 0.0_wp, .false., .true., M - 1)
  call case('a row on no free DOF, two rows 1e-4 apart', 1.0e-4_wp, .true., .true., M - 2, near=1)
  call test_summary()

contains

  subroutine case(what, eps, twin, empty, expected, near)
    character(len=*), intent(in) :: what
    integer, intent(in) :: expected     !< the rank by construction
    integer, intent(in), optional :: near   !< near-kernel directions pinned besides the kernel
    real(wp), intent(in) :: eps         !< the twin row's second coefficient differs by eps
    logical, intent(in) :: twin         !< rows 10 and 11 on the same DOFs
    logical, intent(in) :: empty        !< row 20 has zero coefficients
    type(body_condensed_t) :: bc
    real(wp) :: x(M, M), g(M, M), f(M, M), work(2*M), r(M)
    integer :: i, e, piv(M), rank_ref, info
    ! X = G G' + I, G with entries in [-1/2, 1/2] from a fixed seed
    call random_seed(put=[(7919*i, i=1, 64)])
    call random_number(g)
    g = g - 0.5_wp
    x = matmul(g, transpose(g))
    do i = 1, M
      x(i, i) = x(i, i) + 1.0_wp
    end do
    bc%m = M
    allocate (bc%idx(M), bc%bptr(M + 1), bc%bpos(2*M), bc%bval(2*M))
    bc%idx = [(i, i=1, M)]
    e = 0
    do i = 1, M
      bc%bptr(i) = e + 1
      bc%bpos(e + 1) = i
      bc%bpos(e + 2) = modulo(i, M) + 1
      bc%bval(e + 1) = 1.0_wp
      bc%bval(e + 2) = 0.25_wp
      e = e + 2
    end do
    bc%bptr(M + 1) = e + 1
    if (twin) then   ! row 11 on row 10's DOFs
      bc%bpos(21:22) = bc%bpos(19:20)
      bc%bval(22) = bc%bval(20) + eps
    end if
    if (empty) bc%bval(39:40) = 0.0_wp
    call flex_from_x(bc, x)
    f = bc%flex
    call dpstrf('L', M, f, M, piv, rank_ref, 1.0e-10_wp*maxval([(bc%flex(i, i), i=1, M)]), work, info)
    if (present(near)) rank_ref = rank_ref - near
    call report(info >= 0 .and. bc%rank == rank_ref, what//': the rank of the pivoted Cholesky factor'// &
                trim(merge(' less the near-kernel', '                     ', present(near))), &
                real(bc%rank, wp), real(rank_ref, wp))
    call report(bc%rank == expected, what//': the expected rank', real(bc%rank, wp), real(expected, wp))
    if (bc%rank < M) then
      call report(allocated(bc%kern) .and. bc%prox > 0.0_wp, what//': a kernel basis and a proximal weight')
      if (allocated(bc%kern)) then
        r = matmul(bc%flex, bc%kern(:, 1))
        call report_le(norm2(r)/maxval(abs(bc%flex)), 1.0e-10_wp, what//': F_a z = 0 on the kernel')
        if (present(near)) then
          r = matmul(bc%flex, bc%kern(:, size(bc%kern, 2)))
          call report_le(norm2(r)/maxval(abs(bc%flex)), 1.0e-6_wp, what//': |F_a z| <= 1e-6 |F_a| on the near-kernel')
          call report(size(bc%kern, 2) == M - expected, what//': the basis spans kernel and near-kernel')
        end if
        call report_le(abs(norm2(bc%kern(:, 1)) - 1.0_wp), 1.0e-12_wp, what//': |z| = 1')
      end if
    else
      call report(.not. allocated(bc%kern) .and. bc%prox == 0.0_wp, what//': no kernel, no proximal weight')
    end if
  end subroutine case

end program test_flex_rank
