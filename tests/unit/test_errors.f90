!> The error convention below the driver (module errors): the exit code of each category,
!! the error_t methods, and one real failing call per stage, each returning its category
!! and a message naming the culprit; the driver's half (module fatal_errors): fail_on
!! returns when there is no error.
program test_errors
  use kinds, only: wp, ip
  use fatal_errors, only: fail_on
  use errors, only: error_t, exit_code, ERR_NONE, ERR_INPUT, ERR_NUMERICAL, ERR_IO, ERR_MEMORY, &
                    EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL
  use config, only: body_cfg_t, traction_cfg_t, deck_t, deck_init, SIDE_LEFT, BC_CLAMPED
  use mesh, only: mesh_t
  use assembly, only: assemble_body, body_system_t
  use cholesky, only: chol_t, FACT_CHOLMOD, FACT_BANDED, ORD_AMD, ORD_NATURAL
  use mortar, only: mortar_t, mortar_build
  use budget, only: check_load_range
  use testing, only: grid_mesh, report, test_summary
  implicit none (type, external)

  call test_categories()
  call test_methods()
  call test_assembly()
  call test_factorization()
  call test_mortar()
  call test_budget()
  call test_summary()

contains

  !> Every category has its exit code: input 1, the others 3, none 0.
  subroutine test_categories()
    type(error_t) :: e
    call report(exit_code(e) == EXIT_OK, 'no error: exit code 0')
    call e%set(ERR_INPUT, 'x')
    call report(exit_code(e) == EXIT_INPUT .and. EXIT_INPUT == 1, 'ERR_INPUT: exit code 1')
    call e%set(ERR_NUMERICAL, 'x')
    call report(exit_code(e) == EXIT_NUMERICAL .and. EXIT_NUMERICAL == 3, 'ERR_NUMERICAL: exit code 3')
    call e%set(ERR_IO, 'x')
    call report(exit_code(e) == 3, 'ERR_IO: exit code 3')
    call e%set(ERR_MEMORY, 'x')
    call report(exit_code(e) == 3, 'ERR_MEMORY: exit code 3')
  end subroutine test_categories

  !> set, failed, text, clear; fail_on returns when there is no error.
  subroutine test_methods()
    type(error_t) :: e
    call report(.not. e%failed() .and. e%category == ERR_NONE .and. e%text() == '', 'a new error_t holds none')
    call e%set(ERR_IO, 'cannot write out.h5  ')
    call report(e%failed() .and. e%category == ERR_IO, 'set: failed, with its category')
    call report(e%text() == 'cannot write out.h5', 'set: the message, trailing blanks trimmed')
    call e%clear()
    call report(.not. e%failed() .and. e%text() == '', 'clear: no error, no message')
    call fail_on(e, 'deck x.nml')
    call report(.true., 'fail_on without an error returns')
  end subroutine test_methods

  !> A traction on a group the body does not have is bad input, naming the body and the group.
  subroutine test_assembly()
    type(body_cfg_t) :: body
    type(mesh_t) :: m
    type(body_system_t) :: sys
    type(traction_cfg_t) :: tr(1)
    type(error_t) :: err
    body%id = 1
    body%nx = 3
    body%ny = 2
    body%bc(SIDE_LEFT) = BC_CLAMPED
    call grid_mesh(m, body)
    tr(1)%body = 1
    tr(1)%group = 'no_such_group'
    tr(1)%origin = '&traction 1'
    tr(1)%t0(1:2) = [0.0_wp, -1.0_wp]
    call assemble_body(m, body, .true., tr, 1, sys, err)
    write (*, '(a)') '      message: '//err%text()
    call report(err%category == ERR_INPUT, 'assembly, traction on an unknown group: ERR_INPUT')
    call report(index(err%text(), 'no_such_group') > 0 .and. index(err%text(), 'body 1') > 0, &
                'assembly: the message names the group and the body')
    tr(1)%group = ''
    tr(1)%side = SIDE_LEFT
    call assemble_body(m, body, .true., tr, 1, sys, err)
    call report(.not. err%failed(), 'assembly of a valid body: no error')
  end subroutine test_assembly

  !> An indefinite matrix is a numerical failure for CHOLMOD and the banded Cholesky.
  subroutine test_factorization()
    ! [1 2; 2 1] (eigenvalues 3 and -1), full symmetric CSC, 0-based
    integer(ip), parameter :: colptr(3) = [0, 2, 4], rowind(4) = [0, 1, 0, 1]
    real(wp), parameter :: val(4) = [1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp]
    type(chol_t) :: ch
    type(error_t) :: err
    real(wp) :: b(2)
    call ch%factor(2, colptr, rowind, val, FACT_CHOLMOD, ORD_AMD, err)
    write (*, '(a)') '      message: '//err%text()
    call report(err%category == ERR_NUMERICAL .and. len(err%text()) > 0, 'CHOLMOD, indefinite matrix: ERR_NUMERICAL')
    call ch%factor(2, colptr, rowind, val, FACT_BANDED, ORD_NATURAL, err)
    write (*, '(a)') '      message: '//err%text()
    call report(err%category == ERR_NUMERICAL .and. index(err%text(), 'not positive definite') > 0, &
                'banded, indefinite matrix: ERR_NUMERICAL, "not positive definite"')
    b = 1.0_wp
    call ch%solve(b, err)
    call report(err%category == ERR_NUMERICAL, 'solve after a failed factorization: ERR_NUMERICAL')
    call ch%factor(2, colptr, rowind, [2.0_wp, 1.0_wp, 1.0_wp, 2.0_wp], FACT_CHOLMOD, ORD_AMD, err)
    call report(.not. err%failed(), 'CHOLMOD, positive definite matrix: no error')
    call ch%free()
  end subroutine test_factorization

  !> A slave side without edges is bad input, naming the side.
  subroutine test_mortar()
    real(wp) :: xs(2, 2), xm(2, 2)
    integer :: es(2, 0), em(2, 1)
    type(mortar_t) :: mt
    type(error_t) :: err
    xs = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp], [2, 2])
    xm = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], [2, 2])
    em(:, 1) = [1, 2]
    call mortar_build(xs, es, [.false., .false.], xm, em, mt, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), 'slave') > 0, &
                'mortar, no slave edges: ERR_INPUT naming the slave side ('//err%text()//')')
  end subroutine test_mortar

  !> A traction whose stresses would overflow is bad input, naming the traction; the deck
  !! is left to the driver.
  subroutine test_budget()
    type(deck_t) :: d
    type(error_t) :: err
    integer :: a
    call deck_init(d, 2, 1)
    do a = 1, 2
      d%body(a)%nx = 4
      d%body(a)%ny = 4
      d%body(a)%width = 1.0_wp
      d%body(a)%height = 1.0_wp
    end do
    d%source = 'inputs/x.nml'
    d%ntraction = 1
    allocate (d%traction(1))
    d%traction(1)%body = 2
    d%traction(1)%t0(1:2) = [0.0_wp, -1.0e305_wp]
    call check_load_range(d, err)
    call report(err%category == ERR_INPUT .and. index(err%text(), '&traction 1 (body 2)') > 0, &
                'budget, overflowing traction: ERR_INPUT naming the traction ('//err%text()//')')
    call report(index(err%text(), 'inputs/x.nml') == 0, 'budget: the message leaves the deck to the driver')
    d%traction(1)%t0(1:2) = [0.0_wp, -1.0_wp]
    call check_load_range(d, err)
    call report(.not. err%failed(), 'budget, a representable traction: no error')
  end subroutine test_budget

end program test_errors
