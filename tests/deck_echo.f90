!> Developer driver: read a deck plus command-line overrides with `read_deck` and print the
!! effective deck. Usage: deck_echo DECK.nml [OVERRIDE ...]. Exit 1 (through `fatal`) on
!! bad input, as the main program does. Links only kinds, errors, config, deck.
program deck_echo
  use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
  use errors, only: terminate, EXIT_INPUT
  use config, only: deck_t
  use deck, only: read_deck, print_deck, deck_usage
  implicit none (type, external)
  type(deck_t) :: d
  character(len=:), allocatable :: path
  character(len=4096), allocatable :: overrides(:)
  integer :: n, k, l

  n = command_argument_count()
  if (n < 1) then
    write (error_unit, '(a)') deck_usage
    call terminate(EXIT_INPUT)
  end if
  call get_command_argument(1, length=l)
  allocate (character(len=l) :: path)
  call get_command_argument(1, path)
  allocate (overrides(n - 1))
  do k = 2, n
    call get_command_argument(k, overrides(k - 1))
  end do
  call read_deck(path, overrides, d)
  call print_deck(d, output_unit)
end program deck_echo
