!> Exit codes and the single route for fatal errors.
!! Every fatal error goes through `fatal`, which calls the procedure pointer
!! `fatal_handler`; the default prints one sentence to stderr and exits with the
!! code, without a Fortran runtime message or backtrace. Tests may point the
!! handler elsewhere.
!!
!! Below the driver, a procedure that can fail returns an `error_t` (its category
!! and one sentence); the driver turns the category into the exit code in one
!! place, `exit_code`, and adds the deck's name. See doc/developing.md.
module errors
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
  implicit none (type, external)
  private

  integer, parameter, public :: EXIT_OK = 0             !< converged
  integer, parameter, public :: EXIT_INPUT = 1          !< bad input or usage
  integer, parameter, public :: EXIT_NOT_CONVERGED = 2  !< diverged or max_outer reached
  integer, parameter, public :: EXIT_NUMERICAL = 3      !< numerical failure (not SPD, non-finite, library error)
  integer, parameter, public :: EXIT_INTERRUPTED = 4    !< stopped by SIGTERM/SIGINT after a checkpoint

  !> Categories of an `error_t`: what kind of failure, not where it happened.
  enum, bind(c)
    enumerator :: ERR_NONE = 0   !< no error
    enumerator :: ERR_INPUT      !< the input is wrong (deck, mesh file, checkpoint): exit 1
    enumerator :: ERR_NUMERICAL  !< not SPD, non-finite, a library reports failure: exit 3
    enumerator :: ERR_IO         !< a file cannot be read or written: exit 3
    enumerator :: ERR_MEMORY     !< an allocation failed: exit 3
  end enum
  public :: ERR_NONE, ERR_INPUT, ERR_NUMERICAL, ERR_IO, ERR_MEMORY

  !> An error returned by a procedure below the driver.
  type, public :: error_t
    integer :: category = ERR_NONE            !< one of the ERR_* categories
    character(len=:), allocatable :: message  !< one sentence naming the culprit (body, group, tag, value)
  contains
    procedure :: failed => error_failed
    procedure :: set => error_set
    procedure :: clear => error_clear
    procedure :: text => error_text
  end type error_t

  abstract interface
    !> A fatal-error handler: receives the exit code and the message.
    subroutine fatal_handler_iface(code, msg)
      integer, intent(in) :: code
      character(len=*), intent(in) :: msg
    end subroutine fatal_handler_iface
  end interface

  !> Where fatal errors go (default: print and exit).
  procedure(fatal_handler_iface), pointer, public :: fatal_handler => default_handler

  public :: fatal, terminate, warn, fatal_handler_iface, exit_code, fail_on

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

  !> The exit code of an error's category: the one place where categories meet exit codes.
  pure integer function exit_code(err)
    type(error_t), intent(in) :: err  !< the error
    select case (err%category)
    case (ERR_NONE)
      exit_code = EXIT_OK
    case (ERR_INPUT)
      exit_code = EXIT_INPUT
    case default
      exit_code = EXIT_NUMERICAL
    end select
  end function exit_code

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

  !> True when the error holds a failure.
  elemental logical function error_failed(self)
    class(error_t), intent(in) :: self
    error_failed = self%category /= ERR_NONE
  end function error_failed

  !> Record a failure of `category` with `message`.
  subroutine error_set(self, category, message)
    class(error_t), intent(inout) :: self
    integer, intent(in) :: category           !< one of ERR_INPUT .. ERR_MEMORY
    character(len=*), intent(in) :: message   !< one sentence naming the culprit
    self%category = category
    self%message = trim(message)
  end subroutine error_set

  !> Back to no error.
  subroutine error_clear(self)
    class(error_t), intent(inout) :: self
    self%category = ERR_NONE
    if (allocated(self%message)) deallocate (self%message)
  end subroutine error_clear

  !> The message ('' when none).
  function error_text(self) result(text)
    class(error_t), intent(in) :: self
    character(len=:), allocatable :: text
    if (allocated(self%message)) then
      text = self%message
    else
      text = ''
    end if
  end function error_text

  subroutine default_handler(code, msg)
    integer, intent(in) :: code
    character(len=*), intent(in) :: msg
    write (error_unit, '(a)') 'robin_contact: error: '//trim(msg)
    call terminate(code)
  end subroutine default_handler

end module errors
