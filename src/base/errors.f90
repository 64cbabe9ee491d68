!> Exit codes and the single route for fatal errors.
!! Every fatal error goes through `fatal`, which calls the procedure pointer
!! `fatal_handler`; the default prints one sentence to stderr and exits with the
!! code, without a Fortran runtime message or backtrace. Tests may point the
!! handler elsewhere.
module errors
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  implicit none (type, external)
  private

  integer, parameter, public :: EXIT_OK = 0             !< converged
  integer, parameter, public :: EXIT_INPUT = 1          !< bad input or usage
  integer, parameter, public :: EXIT_NOT_CONVERGED = 2  !< diverged or max_outer reached
  integer, parameter, public :: EXIT_NUMERICAL = 3      !< numerical failure (not SPD, non-finite, library error)
  integer, parameter, public :: EXIT_INTERRUPTED = 4    !< stopped by SIGTERM/SIGINT after a checkpoint

  abstract interface
    !> A fatal-error handler: receives the exit code and the message.
    subroutine fatal_handler_iface(code, msg)
      integer, intent(in) :: code
      character(len=*), intent(in) :: msg
    end subroutine fatal_handler_iface
  end interface

  !> Where fatal errors go (default: print and exit).
  procedure(fatal_handler_iface), pointer, public :: fatal_handler => default_handler

  public :: fatal, terminate, warn, fatal_handler_iface

contains

  !> Report a fatal error with its exit code and one sentence naming the culprit.
  subroutine fatal(code, msg)
    integer, intent(in) :: code           !< one of the EXIT_* codes
    character(len=*), intent(in) :: msg   !< what went wrong, naming the input, body and value
    call fatal_handler(code, msg)
    ! A handler that returns is not allowed to continue the computation.
    call terminate(code)
  end subroutine fatal

  !> Print a warning line to stderr (the run continues).
  subroutine warn(msg)
    character(len=*), intent(in) :: msg  !< warning text
    write (error_unit, '(a)') 'robin_contact: warning: '//trim(msg)
  end subroutine warn

  !> Flush the standard units and exit with `code`, silently.
  subroutine terminate(code)
    integer, intent(in) :: code  !< process exit status
    flush (output_unit)
    flush (error_unit)
    select case (code)
    case (0)
      stop 0, quiet=.true.
    case (1)
      stop 1, quiet=.true.
    case (2)
      stop 2, quiet=.true.
    case (3)
      stop 3, quiet=.true.
    case (4)
      stop 4, quiet=.true.
    case default
      stop 3, quiet=.true.
    end select
  end subroutine terminate

  subroutine default_handler(code, msg)
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    write (error_unit, '(a)') 'robin_contact: error: '//trim(msg)
    call terminate(code)
  end subroutine default_handler

end module errors
