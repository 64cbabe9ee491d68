!> Small HDF5 helpers: write and read datasets and attributes of the kinds the result
!! and checkpoint files use (real and integer arrays of rank 1 and 2, scalars, text).
module h5io
  use kinds, only: wp
  use hdf5
  implicit none
  private

  public :: dset_r1, dset_r2, dset_i1, dset_i2, dset_str, attr_str, attr_int, attr_real
  public :: read_r1, read_r2, read_i1, read_str, read_attr_int, read_attr_real

contains

  subroutine dset_r1(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: v(:)
    integer(hid_t) :: sp, ds
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = size(v)
    call h5screate_simple_f(1, dims, sp, err)
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, sp, ds, err)
    if (size(v) > 0) call h5dwrite_f(ds, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5dclose_f(ds, err)
    call h5sclose_f(sp, err)
  end subroutine dset_r1

  subroutine dset_r2(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in), contiguous :: v(:, :)
    integer(hid_t) :: sp, ds
    integer(hsize_t) :: dims(2)
    integer :: err
    dims = shape(v)
    call h5screate_simple_f(2, dims, sp, err)
    call h5dcreate_f(loc, name, H5T_NATIVE_DOUBLE, sp, ds, err)
    if (size(v) > 0) call h5dwrite_f(ds, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5dclose_f(ds, err)
    call h5sclose_f(sp, err)
  end subroutine dset_r2

  subroutine dset_i1(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: v(:)
    integer(hid_t) :: sp, ds
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = size(v)
    call h5screate_simple_f(1, dims, sp, err)
    call h5dcreate_f(loc, name, H5T_NATIVE_INTEGER, sp, ds, err)
    if (size(v) > 0) call h5dwrite_f(ds, H5T_NATIVE_INTEGER, v, dims, err)
    call h5dclose_f(ds, err)
    call h5sclose_f(sp, err)
  end subroutine dset_i1

  subroutine dset_i2(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in), contiguous :: v(:, :)
    integer(hid_t) :: sp, ds
    integer(hsize_t) :: dims(2)
    integer :: err
    dims = shape(v)
    call h5screate_simple_f(2, dims, sp, err)
    call h5dcreate_f(loc, name, H5T_NATIVE_INTEGER, sp, ds, err)
    if (size(v) > 0) call h5dwrite_f(ds, H5T_NATIVE_INTEGER, v, dims, err)
    call h5dclose_f(ds, err)
    call h5sclose_f(sp, err)
  end subroutine dset_i2

  subroutine dset_str(loc, name, s)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name, s
    integer(hid_t) :: sp, ds, ty
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = 1
    call h5tcopy_f(H5T_FORTRAN_S1, ty, err)
    call h5tset_size_f(ty, int(max(1, len(s)), size_t), err)
    call h5screate_f(H5S_SCALAR_F, sp, err)
    call h5dcreate_f(loc, name, ty, sp, ds, err)
    call h5dwrite_f(ds, ty, s, dims, err)
    call h5dclose_f(ds, err)
    call h5sclose_f(sp, err)
    call h5tclose_f(ty, err)
  end subroutine dset_str

  subroutine attr_str(loc, name, s)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name, s
    integer(hid_t) :: sp, at, ty
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = 1
    call h5tcopy_f(H5T_FORTRAN_S1, ty, err)
    call h5tset_size_f(ty, int(max(1, len(s)), size_t), err)
    call h5screate_f(H5S_SCALAR_F, sp, err)
    call h5acreate_f(loc, name, ty, sp, at, err)
    if (len(s) > 0) then
      call h5awrite_f(at, ty, s, dims, err)
    else
      call h5awrite_f(at, ty, ' ', dims, err)
    end if
    call h5aclose_f(at, err)
    call h5sclose_f(sp, err)
    call h5tclose_f(ty, err)
  end subroutine attr_str

  subroutine attr_int(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: v
    integer(hid_t) :: sp, at
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = 1
    call h5screate_f(H5S_SCALAR_F, sp, err)
    call h5acreate_f(loc, name, H5T_NATIVE_INTEGER, sp, at, err)
    call h5awrite_f(at, H5T_NATIVE_INTEGER, v, dims, err)
    call h5aclose_f(at, err)
    call h5sclose_f(sp, err)
  end subroutine attr_int

  subroutine attr_real(loc, name, v)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(in) :: v
    integer(hid_t) :: sp, at
    integer(hsize_t) :: dims(1)
    integer :: err
    dims = 1
    call h5screate_f(H5S_SCALAR_F, sp, err)
    call h5acreate_f(loc, name, H5T_NATIVE_DOUBLE, sp, at, err)
    call h5awrite_f(at, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5aclose_f(at, err)
    call h5sclose_f(sp, err)
  end subroutine attr_real


  !> Read a real dataset of rank 1 into v (allocated to the stored size).
  subroutine read_r1(loc, name, v, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(out) :: v(:)
    integer, intent(out) :: err
    integer(hid_t) :: ds, sp
    integer(hsize_t) :: dims(1), maxd(1)
    call h5dopen_f(loc, name, ds, err)
    if (err /= 0) return
    call h5dget_space_f(ds, sp, err)
    call h5sget_simple_extent_dims_f(sp, dims, maxd, err)
    allocate (v(dims(1)))
    err = 0
    if (dims(1) > 0) call h5dread_f(ds, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5sclose_f(sp, err)
    call h5dclose_f(ds, err)
  end subroutine read_r1

  !> Read a real dataset of rank 2 (Fortran shape) into v.
  subroutine read_r2(loc, name, v, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), allocatable, intent(out) :: v(:, :)
    integer, intent(out) :: err
    integer(hid_t) :: ds, sp
    integer(hsize_t) :: dims(2), maxd(2)
    call h5dopen_f(loc, name, ds, err)
    if (err /= 0) return
    call h5dget_space_f(ds, sp, err)
    call h5sget_simple_extent_dims_f(sp, dims, maxd, err)
    allocate (v(dims(1), dims(2)))
    err = 0
    if (size(v) > 0) call h5dread_f(ds, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5sclose_f(sp, err)
    call h5dclose_f(ds, err)
  end subroutine read_r2

  !> Read an integer dataset of rank 1 into v.
  subroutine read_i1(loc, name, v, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, allocatable, intent(out) :: v(:)
    integer, intent(out) :: err
    integer(hid_t) :: ds, sp
    integer(hsize_t) :: dims(1), maxd(1)
    call h5dopen_f(loc, name, ds, err)
    if (err /= 0) return
    call h5dget_space_f(ds, sp, err)
    call h5sget_simple_extent_dims_f(sp, dims, maxd, err)
    allocate (v(dims(1)))
    err = 0
    if (dims(1) > 0) call h5dread_f(ds, H5T_NATIVE_INTEGER, v, dims, err)
    call h5sclose_f(sp, err)
    call h5dclose_f(ds, err)
  end subroutine read_i1

  !> Read a scalar fixed-length string dataset.
  subroutine read_str(loc, name, s, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=:), allocatable, intent(out) :: s
    integer, intent(out) :: err
    integer(hid_t) :: ds, ty
    integer(size_t) :: n
    integer(hsize_t) :: dims(1)
    dims = 1
    call h5dopen_f(loc, name, ds, err)
    if (err /= 0) return
    call h5dget_type_f(ds, ty, err)
    call h5tget_size_f(ty, n, err)
    allocate (character(len=n) :: s)
    call h5dread_f(ds, ty, s, dims, err)
    call h5tclose_f(ty, err)
    call h5dclose_f(ds, err)
  end subroutine read_str

  !> Read a scalar integer attribute.
  subroutine read_attr_int(loc, name, v, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(out) :: v
    integer, intent(out) :: err
    integer(hid_t) :: at
    integer(hsize_t) :: dims(1)
    dims = 1
    v = 0
    call h5aopen_f(loc, name, at, err)
    if (err /= 0) return
    call h5aread_f(at, H5T_NATIVE_INTEGER, v, dims, err)
    call h5aclose_f(at, err)
  end subroutine read_attr_int

  !> Read a scalar real attribute.
  subroutine read_attr_real(loc, name, v, err)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    real(wp), intent(out) :: v
    integer, intent(out) :: err
    integer(hid_t) :: at
    integer(hsize_t) :: dims(1)
    dims = 1
    v = 0.0_wp
    call h5aopen_f(loc, name, at, err)
    if (err /= 0) return
    call h5aread_f(at, H5T_NATIVE_DOUBLE, v, dims, err)
    call h5aclose_f(at, err)
  end subroutine read_attr_real

end module h5io
