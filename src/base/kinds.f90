!> Kind parameters used throughout robin_contact: one real kind, integer kinds, C kinds.
module kinds
  use, intrinsic :: iso_fortran_env, only: real64, int32, int64
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_null_ptr, c_char, c_long
  implicit none (type, external)
  private
  integer, parameter, public :: wp = real64   !< working real kind (double precision)
  integer, parameter, public :: ip = int32    !< default integer kind
  integer, parameter, public :: i8 = int64    !< large counters (bytes, flops)
  public :: c_int, c_double, c_ptr, c_null_ptr, c_char, c_long
end module kinds
