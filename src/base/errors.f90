!> Exit codes and errors: `error_t` (a category and one sentence), which every procedure
!! below the driver that can fail returns, and `exit_code`, the one place where a category
!! becomes an exit code; `warn` prints a warning line. The driver alone ends a run on an
!! error (module fatal_errors: fail_on, which adds the deck's name, and fatal). See
!! doc/developing.md, "How errors travel".
module errors
  use, intrinsic :: iso_fortran_env, only: error_unit
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

  public :: warn, exit_code

contains

  !> Print a warning line to stderr (the run continues).
  subroutine warn(msg)
    character(len=*), intent(in) :: msg  !< warning text
    write (error_unit, '(a)') 'robin_contact: warning: '//trim(msg)
  end subroutine warn

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

end module errors
