!> The one wall clock of the program and its tests.
module clock
  use kinds, only: wp
  use omp_lib, only: omp_get_wtime
  implicit none (type, external)
  private

  public :: wtime

contains

  !> Wall-clock time [s] since an arbitrary origin (OpenMP's clock: monotonic, thread-safe).
  function wtime() result(t)
    real(wp) :: t
    t = omp_get_wtime()
  end function wtime

end module clock
