!> Tests of h5io's reserved datasets and of files' writes at offsets: a real (3, 4) and an
!! integer dataset created with their storage reserved, the file closed, their data written
!! beside the library at the offsets it returned (the second before the first), then read
!! back through HDF5 with their `units` attribute; a dataset with no element and a write
!! to a closed descriptor are failures.
program test_h5io
  use, intrinsic :: iso_c_binding, only: c_loc, c_long_long
  use kinds, only: wp
  use hdf5, only: hid_t, haddr_t, hsize_t, h5dopen_f, h5dclose_f
  use h5io, only: file_open, file_close, group_open, group_close, reserve_dset, read_dset, describe, exists, &
                  CLASS_REAL, CLASS_INTEGER, CLASS_VSTRING
  use files, only: data_open, data_write, data_close
  use errors, only: error_t, ERR_IO
  use testing, only: report, test_summary, scratch_path
  implicit none (type, external)
  character(len=:), allocatable :: path
  real(wp), target :: a(3, 4)
  integer, target :: ids(5)
  real(wp), allocatable :: a2(:, :)
  integer, allocatable :: ids2(:)
  integer(hsize_t), allocatable :: dims(:)
  integer(hid_t) :: fid, gid, did
  integer(haddr_t) :: off_a, off_i, off_0
  type(error_t) :: st, st0, werr
  integer :: fd, i, j, cls, e

  ! the file build/<kind>/test-h5io.h5 (beside the folder of this program): a release and a
  ! checked make check running at once share none
  path = scratch_path('test-h5io.h5')
  do j = 1, 4
    do i = 1, 3
      a(i, j) = real(10*i + j, wp) + 0.125_wp
    end do
  end do
  ids = [(-i, i=1, 5)]
  call file_open(path, fid, st, create=.true.)
  call group_open(fid, 'g', gid, st, create=.true.)
  call reserve_dset(gid, 'a', [3_hsize_t, 4_hsize_t], .false., off_a, st, 'm')
  call reserve_dset(gid, 'ids', [5_hsize_t], .true., off_i, st, '1')
  call report(.not. st%failed() .and. off_a >= 0 .and. off_i >= 0 .and. off_a /= off_i, 'reserve_dset: two offsets')
  call reserve_dset(gid, 'none', [0_hsize_t], .false., off_0, st0)
  call report(st0%failed() .and. off_0 == -1, 'reserve_dset: no element is a failure')
  call group_close(gid, st)
  call file_close(fid, st)
  call data_open(path, fd, werr)
  call report(fd >= 0 .and. .not. werr%failed(), 'data_open')
  call data_write(fd, c_loc(ids), int(storage_size(ids)/8*size(ids), c_long_long), int(off_i, c_long_long), werr)
  call report(.not. werr%failed(), 'data_write: the integers')
  call data_write(fd, c_loc(a), int(storage_size(a)/8*size(a), c_long_long), int(off_a, c_long_long), werr)
  call report(.not. werr%failed(), 'data_write: the reals')
  call data_close(fd, werr)
  call report(fd == -1 .and. .not. werr%failed(), 'data_close')

  call file_open(path, fid, st)
  call read_dset(fid, 'g/a', a2, st)
  call report(.not. st%failed() .and. all(shape(a2) == [3, 4]), 'read back: shape (3, 4)')
  if (all(shape(a2) == [3, 4])) call report(all(a2 == a), 'read back: the reals as written')
  call read_dset(fid, 'g/ids', ids2, st)
  call report(.not. st%failed() .and. size(ids2) == 5, 'read back: 5 integers')
  if (size(ids2) == 5) call report(all(ids2 == ids), 'read back: the integers as written')
  call group_open(fid, 'g', gid, st)
  call describe(gid, 'a', .false., cls, dims, st)
  call report(cls == CLASS_REAL, 'the reals are a real dataset')
  call describe(gid, 'ids', .false., cls, dims, st)
  call report(cls == CLASS_INTEGER, 'the integers are an integer dataset')
  call report(exists(gid, 'none', .false.) .eqv. .false., 'the failed reservation left no dataset')
  call h5dopen_f(gid, 'a', did, e)
  call describe(did, 'units', .true., cls, dims, st)
  call report(e == 0 .and. cls == CLASS_VSTRING, 'the reals have their units attribute')
  call h5dclose_f(did, e)
  call group_close(gid, st)
  call file_close(fid, st)
  call report(.not. st%failed(), 'reading: no failure')

  ! a closed descriptor: the write fails with the system's reason
  call data_write(fd, c_loc(a), 8_c_long_long, 0_c_long_long, werr)
  call report(werr%category == ERR_IO .and. len_trim(werr%text()) > 0, &
              'data_write on a closed descriptor fails ('//werr%text()//')')
  call test_summary()
end program test_h5io
