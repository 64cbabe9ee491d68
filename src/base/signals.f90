!> SIGTERM/SIGINT (and SIGUSR1, which OpenMPI's mpirun forwards to its ranks) from a batch scheduler: the C handler (src/base/sighdl.c) sets a flag
!! that the outer iteration polls through `stop_requested`.
module signals
  use, intrinsic :: iso_c_binding, only: c_int
  implicit none (type, external)
  private

  interface
    integer(c_int) function rc_signals_install() bind(c, name='rc_signals_install')
      import :: c_int
    end function rc_signals_install
    integer(c_int) function rc_signals_pending() bind(c, name='rc_signals_pending')
      import :: c_int
    end function rc_signals_pending
  end interface

  abstract interface
    !> A stop hook (stop_requested is one): true when the caller must stop at its next
    !! stopping point (an MPRGP solve: its next step; the contact iteration: the end of the
    !! outer iteration).
    logical function stop_iface()
    end function stop_iface
  end interface
  public :: signals_install, stop_requested, pending_signal, stop_iface

contains

  !> Install the handlers; .false. if the system refused.
  logical function signals_install()
    signals_install = rc_signals_install() == 0
  end function signals_install

  !> True once SIGTERM, SIGINT or SIGUSR1 has been received.
  logical function stop_requested()
    stop_requested = rc_signals_pending() /= 0
  end function stop_requested

  !> The signal number received, 0 if none.
  integer function pending_signal()
    pending_signal = int(rc_signals_pending())
  end function pending_signal

end module signals
