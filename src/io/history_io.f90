!> The group /history of result and checkpoint files (one entry per outer iteration):
!! one writer and one reader, so both files name its datasets the same way.
module history_io
  use kinds, only: wp
  use hdf5, only: hid_t
  use h5io, only: group_open, group_close, write_dset, read_dset
  use errors, only: error_t, ERR_IO
  use contact_types, only: contact_result_t
  implicit none (type, external)
  private

  public :: write_history, read_history

contains

  !> Write the group /history of an open file from the first res%nhist entries; units:
  !! '1' (relative criterion and residual, counts), 's' (wall time).
  subroutine write_history(fid, res, st)
    integer(hid_t), intent(in) :: fid              !< open file
    type(contact_result_t), intent(in) :: res      !< history source
    type(error_t), intent(inout) :: st         !< status (first failure kept)
    integer(hid_t) :: gid
    call group_open(fid, 'history', gid, st, create=.true.)
    call write_dset(gid, 'criterion', res%h_criterion(1:res%nhist), st, '1')
    call write_dset(gid, 'residual', res%h_residual(1:res%nhist), st, '1')
    call write_dset(gid, 'inner', res%h_inner(1:res%nhist), st, '1')
    call write_dset(gid, 'active', res%h_active(1:res%nhist), st, '1')
    call write_dset(gid, 'wall_s', res%h_wall(1:res%nhist), st, 's')
    call group_close(gid, st)
  end subroutine write_history

  !> Read the first n entries of /history into res%h_* (allocated with at least n
  !! entries by the caller); a failure if the file holds fewer.
  subroutine read_history(fid, n, res, st)
    integer(hid_t), intent(in) :: fid              !< open file
    integer, intent(in) :: n                       !< entries to read
    type(contact_result_t), intent(inout) :: res   !< receives the history
    type(error_t), intent(inout) :: st         !< status (first failure kept)
    integer(hid_t) :: gid
    real(wp), allocatable :: crit(:), resid(:), wall(:)
    integer, allocatable :: inner(:), active(:)
    call group_open(fid, 'history', gid, st)
    call read_dset(gid, 'criterion', crit, st)
    call read_dset(gid, 'residual', resid, st)
    call read_dset(gid, 'wall_s', wall, st)
    call read_dset(gid, 'inner', inner, st)
    call read_dset(gid, 'active', active, st)
    call group_close(gid, st)
    if (st%failed()) return
    if (min(size(crit), size(resid), size(wall), size(inner), size(active)) < n) then
      call st%set(ERR_IO, 'the history is shorter than the outer iterations done')
      return
    end if
    res%h_criterion(1:n) = crit(1:n)
    res%h_residual(1:n) = resid(1:n)
    res%h_wall(1:n) = wall(1:n)
    res%h_inner(1:n) = inner(1:n)
    res%h_active(1:n) = active(1:n)
  end subroutine read_history

end module history_io
