!> Unit tests of the body factorization type (module factorization): the factory picks the
!! extension the deck's setting names; CHOLMOD and the banded factor solve a small SPD K and
!! give (K^-1) on the interface DOFs against the inverse written out by hand; every failure
!! (an indefinite K, a solve or an inverse without a factorization, MUMPS in the serial
!! binary, a condensed body's displacement recovery on a failed factor) is an error_t with a
!! message, and no NaN reaches the caller's vector.
!! One line per check: PASS/FAIL. Exits with status 1 if any check failed.
program test_factorization
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
  use kinds, only: wp, ip
  use config, only: factor_cfg_t, FACTOR_CHOLMOD, FACTOR_BANDED, FACTOR_MUMPS, ORDER_ND, ORDER_AMD
  use errors, only: error_t, ERR_NUMERICAL, ERR_INPUT
  use factorization, only: factor_t, cholmod_factor_t, banded_factor_t, mumps_factor_t, new_factor
  use mumps_iface, only: mumps_built
  use assembly, only: body_system_t
  use condense, only: body_condensed_t, recover_displacement
  use testing, only: report, test_summary
  implicit none (type, external)

  ! K = [4 1 0; 1 3 1; 0 1 2], full symmetric CSC, 0-based; det K = 18
  integer(ip), parameter :: colptr(4) = [0_ip, 2_ip, 5_ip, 7_ip]
  integer(ip), parameter :: rowind(7) = [0_ip, 1_ip, 0_ip, 1_ip, 2_ip, 1_ip, 2_ip]
  real(wp), parameter :: kval(7) = [4.0_wp, 1.0_wp, 1.0_wp, 3.0_wp, 1.0_wp, 1.0_wp, 2.0_wp]
  ! an indefinite one on the same pattern: [1 2 0; 2 1 2; 0 2 1]
  real(wp), parameter :: bad(7) = [1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp]

  call test_factory()
  call test_spd(FACTOR_CHOLMOD, ORDER_ND, 'cholmod/nd')
  call test_spd(FACTOR_CHOLMOD, ORDER_AMD, 'cholmod/amd')
  call test_spd(FACTOR_BANDED, ORDER_ND, 'banded')
  call test_failures(FACTOR_CHOLMOD, 'cholmod')
  call test_failures(FACTOR_BANDED, 'banded')
  call test_mumps_serial()
  call test_recover_failure()
  call test_summary()

contains

  !> The setting picks the extension.
  subroutine test_factory()
    type(factor_cfg_t) :: fc
    class(factor_t), allocatable :: f
    fc%factorization = FACTOR_CHOLMOD
    call new_factor(fc, 1, f)
    call report(kind_of(f) == 'cholmod' .and. f%wants_interior_order(), &
                'factory: cholmod with ordering=nd, which takes an interior order')
    fc%factorization = FACTOR_BANDED
    call new_factor(fc, 1, f)
    call report(kind_of(f) == 'banded' .and. .not. f%wants_interior_order() .and. f%holds_result(), &
                'factory: banded')
    fc%factorization = FACTOR_MUMPS
    call new_factor(fc, 1, f)
    call report(kind_of(f) == 'mumps' .and. f%distributed, 'factory: mumps, distributed')
  end subroutine test_factory

  !> Solve and interface inverse of the SPD K against the formulas.
  subroutine test_spd(method, ordering, what)
    integer, intent(in) :: method, ordering
    character(len=*), intent(in) :: what
    type(factor_cfg_t) :: fc
    class(factor_t), allocatable :: f
    type(error_t) :: err
    real(wp) :: u(3), x(2, 2), xref(2, 2)
    fc%factorization = method
    fc%ordering = ordering
    call new_factor(fc, 1, f)
    if (f%wants_interior_order()) then
      call f%factorize(3, [2, 3], err, colptr, rowind, kval, interior_perm=[1])
    else
      call f%factorize(3, [2, 3], err, colptr, rowind, kval)
    end if
    call report(.not. err%failed(), what//': K factorized '//err%text())
    if (err%failed()) return
    u = [6.0_wp, 10.0_wp, 8.0_wp]          ! K [1 2 3]'
    call f%solve(u, err)
    call report(.not. err%failed() .and. maxval(abs(u - [1.0_wp, 2.0_wp, 3.0_wp])) <= 1.0e-14_wp, &
                what//': K u = K [1 2 3]'' gives [1 2 3]', maxval(abs(u - [1.0_wp, 2.0_wp, 3.0_wp])), 1.0e-14_wp)
    xref = reshape([8.0_wp, -4.0_wp, -4.0_wp, 11.0_wp], [2, 2])/18.0_wp
    call f%interface_inverse([2, 3], x, err)
    call report(.not. err%failed() .and. maxval(abs(x - xref)) <= 1.0e-15_wp, &
                what//': (K^-1)(2:3, 2:3) = [8 -4; -4 11]/18', maxval(abs(x - xref)), 1.0e-15_wp)
    call report(f%stats%mem_bytes > 0.0_wp .and. len(f%summary()) > 0, what//': stats and summary ('//f%summary()//')')
    call f%free()
    u = 1.0_wp
    call f%solve(u, err)
    call report(err%failed() .and. .not. any(ieee_is_nan(u)), what//': a solve after free is an error ('//err%text()//')')
  end subroutine test_spd

  !> An indefinite K, and a solve or an inverse after it: errors, no NaN.
  subroutine test_failures(method, what)
    integer, intent(in) :: method
    character(len=*), intent(in) :: what
    type(factor_cfg_t) :: fc
    class(factor_t), allocatable :: f
    type(error_t) :: err
    real(wp) :: u(3), x(2, 2)
    fc%factorization = method
    fc%ordering = ORDER_AMD
    call new_factor(fc, 2, f)
    call f%factorize(3, [2, 3], err, colptr, rowind, bad)
    call report(err%failed() .and. err%category == ERR_NUMERICAL, &
                what//': an indefinite K is a numerical error ('//err%text()//')')
    u = [1.0_wp, 2.0_wp, 3.0_wp]
    call f%solve(u, err)
    call report(err%failed() .and. .not. any(ieee_is_nan(u)), &
                what//': a solve on the failed factor is an error, no NaN ('//err%text()//')')
    x = 0.0_wp
    call f%interface_inverse([2, 3], x, err)
    call report(err%failed() .and. .not. any(ieee_is_nan(x)), &
                what//': the interface inverse of the failed factor is an error ('//err%text()//')')
    call f%factorize(3, [2, 3], err, irn=[1], jcn=[1], tval=[1.0_wp])
    call report(err%failed(), what//': triplet (MUMPS) input refused ('//err%text()//')')
  end subroutine test_failures

  !> The serial binary has no MUMPS: factorize is an input error naming the MPI binary.
  subroutine test_mumps_serial()
    type(factor_cfg_t) :: fc
    class(factor_t), allocatable :: f
    type(error_t) :: err
    real(wp) :: u(3)
    if (mumps_built) return
    fc%factorization = FACTOR_MUMPS
    call new_factor(fc, 1, f)
    call f%factorize(3, [2, 3], err, irn=[1, 2, 3], jcn=[1, 2, 3], tval=[1.0_wp, 1.0_wp, 1.0_wp])
    call report(err%failed() .and. err%category == ERR_INPUT .and. index(err%text(), 'robin_contact_mpi') > 0, &
                'mumps in the serial binary: an input error ('//err%text()//')')
    u = 1.0_wp
    call f%solve(u, err)
    call report(err%failed() .and. all(u == 1.0_wp), 'mumps: a solve without a factorization is an error')
  end subroutine test_mumps_serial

  !> A condensed body whose factor failed: recovering its displacement is an error and
  !! leaves u_free as it was (it used to come back as NaN).
  subroutine test_recover_failure()
    type(factor_cfg_t) :: fc
    type(body_condensed_t) :: cbody
    type(body_system_t) :: sys
    type(error_t) :: err
    real(wp) :: ufree(3)
    fc%factorization = FACTOR_CHOLMOD
    fc%ordering = ORDER_AMD
    call new_factor(fc, 1, cbody%fac)
    call cbody%fac%factorize(3, [integer ::], err, colptr, rowind, bad)
    call report(err%failed(), 'recover: the body''s factorization failed')
    sys%n = 3
    sys%f = [1.0_wp, 1.0_wp, 1.0_wp]
    cbody%m = 0
    cbody%idx = [integer ::]
    cbody%bptr = [1]
    cbody%bpos = [integer ::]
    cbody%bval = [real(wp) ::]
    cbody%u0 = [0.0_wp, 0.0_wp, 0.0_wp]
    ufree = 7.0_wp
    call recover_displacement(sys, cbody, [real(wp) ::], ufree, err)
    call report(err%failed() .and. all(ufree == 7.0_wp), &
                'recover: a failed solve is an error_t, u_free untouched, no NaN ('//err%text()//')')
  end subroutine test_recover_failure

  !> The extension of a factor, as a word.
  function kind_of(f) result(w)
    class(factor_t), intent(in) :: f
    character(len=:), allocatable :: w
    select type (f)
    type is (cholmod_factor_t)
      w = 'cholmod'
    type is (banded_factor_t)
      w = 'banded'
    type is (mumps_factor_t)
      w = 'mumps'
    class default
      w = '?'
    end select
  end function kind_of

end program test_factorization
