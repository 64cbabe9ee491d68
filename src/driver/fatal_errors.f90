!> The driver's end of the error convention: the single route by which a run stops on an
!! error. `fail_on` turns an `error_t` (module errors) into its exit code and message, with
!! the driver's context in front; `fatal` calls the procedure pointer `fatal_handler`, whose
!! default prints one sentence to stderr and exits with the code, without a Fortran runtime
!! message or backtrace (the MPI binary points it at the ranks' route, run_state's
!! par_fatal). Only the driver uses this module: every procedure below it returns an
!! `error_t` instead. See doc/developing.md, "How errors travel".
module fatal_errors
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  use errors, only: error_t, exit_code
  implicit none (type, external)
  private

  abstract interface
    !> A fatal-error handler: receives the exit code and the message.
    subroutine fatal_handler_iface(code, msg)
      integer, intent(in) :: code
      character(len=*), intent(in) :: msg
    end subroutine fatal_handler_iface
  end interface

  !> Where fatal errors go (default: print and exit).
  procedure(fatal_handler_iface), pointer, public :: fatal_handler => default_handler

  public :: fatal, fail_on, terminate, fatal_handler_iface

contains

  !> Report a fatal error with its exit code and one sentence naming the culprit.
  subroutine fatal(code, msg)
    integer, intent(in) :: code           !< one of the EXIT_* codes
    character(len=*), intent(in) :: msg   !< what went wrong, naming the input, body and value
    call fatal_handler(code, msg)
    ! A handler that returns is not allowed to continue the computation.
    call terminate(code)
  end subroutine fatal

  !> Stop the run with `err`'s exit code when it holds an error; `context` (the deck, say)
  !! is put in front of the message.
  subroutine fail_on(err, context)
    type(error_t), intent(in) :: err              !< the error, possibly none
    character(len=*), intent(in), optional :: context  !< prefix such as "deck inputs/x.nml"
    if (.not. err%failed()) return
    if (present(context)) then
      call fatal(exit_code(err), trim(context)//': '//err%text())
    else
      call fatal(exit_code(err), err%text())
    end if
  end subroutine fail_on

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

end module fatal_errors
