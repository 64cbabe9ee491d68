!> The command line: DECK [OVERRIDE ...] [--restart FILE]. `--help`, `--version` and
!! `--deck-reference` (anywhere) print to standard output and exit 0 without a deck; any
!! other argument that starts with '-' is an unknown option (exit 1).
module command_line
  use errors, only: EXIT_OK, EXIT_INPUT, EXIT_NUMERICAL
  use fatal_errors, only: fatal, terminate
  use deck, only: deck_usage, deck_reference
  use config, only: program_version
  use sysinfo, only: write_stdout_checked
  use mpi_env, only: par_finalize
  implicit none (type, external)
  private

  public :: parse_arguments

contains

  !> The deck's path, its overrides and the checkpoint to restart from ('' none).
  subroutine parse_arguments(rank, path, extra, restart)
    integer, intent(in) :: rank                                  !< this rank (0 prints)
    character(len=:), allocatable, intent(out) :: path           !< the deck file
    character(len=4096), allocatable, intent(out) :: extra(:)    !< the overrides, in order
    character(len=:), allocatable, intent(out) :: restart        !< --restart FILE, or ''
    integer :: n, i, l, k
    character(len=4096) :: arg
    character(len=*), parameter :: OPTIONS = 'the options are --help, --version, --deck-reference '// &
      'and --restart FILE.ckpt.h5 (robin_contact --help)'
    n = command_argument_count()
    i = 1
    do while (i <= n)
      call get_command_argument(i, arg, l)
      select case (trim(arg))
      case ('-h', '--help')
        call print_and_exit(rank, deck_usage)
      case ('--version')
        call print_and_exit(rank, 'robin_contact '//program_version)
      case ('--deck-reference')
        call print_and_exit(rank, deck_reference())
      case ('--restart')
        i = i + 1   ! its file is not an option
      case default
        if (arg(1:1) == '-' .and. len_trim(arg) > 1) call fatal(EXIT_INPUT, 'unknown option '''// &
          trim(arg)//'''; '//OPTIONS)
      end select
      i = i + 1
    end do
    if (n < 1) call fatal(EXIT_INPUT, 'no deck file given'//achar(10)//deck_usage)
    call get_command_argument(1, arg, l)
    if (trim(arg) == '--restart') call fatal(EXIT_INPUT, 'no deck file given: the deck comes '// &
      'first, robin_contact DECK.nml [OVERRIDE ...] --restart FILE.ckpt.h5')
    path = trim(arg)
    restart = ''
    allocate (extra(n - 1))
    k = 0
    i = 2
    do while (i <= n)
      call get_command_argument(i, arg, l)
      if (l > len(arg)) call fatal(EXIT_INPUT, 'command-line argument too long')
      if (trim(arg) == '--restart') then
        if (i == n) call fatal(EXIT_INPUT, '--restart needs a checkpoint file (FILE.ckpt.h5)')
        call get_command_argument(i + 1, arg, l)
        restart = trim(arg)
        i = i + 2
        cycle
      end if
      k = k + 1
      extra(k) = arg
      i = i + 1
    end do
    extra = extra(1:k)
  end subroutine parse_arguments

  !> Write `text` (lines separated by LF, a final LF optional) to standard output (rank 0's
  !! in the MPI binary) and end the program with exit code 0 (3 if it cannot be written).
  subroutine print_and_exit(rank, text)
    integer, intent(in) :: rank
    character(len=*), intent(in) :: text
    integer :: err, n
    n = len(text)
    if (n > 0) then
      if (text(n:n) == achar(10)) n = n - 1
    end if
    err = 0
    if (rank == 0) call write_stdout_checked(text(1:n), err)
    if (err /= 0) call fatal(EXIT_NUMERICAL, 'cannot write to standard output (full disk or closed pipe?)')
    call par_finalize()
    call terminate(EXIT_OK)
  end subroutine print_and_exit

end module command_line
