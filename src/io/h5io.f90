!> HDF5 access for the result and checkpoint files: files, groups, and one path each
!! to write and to read a dataset or an attribute of the kinds the files hold (real and
!! integer arrays of any rank, real and integer scalars, text).
!!
!! Every call takes an `error_t` (ERR_IO) that keeps the first failure (what could not be done
!! to which object); once it is set, writes and reads do nothing and only closing still
!! happens, so a caller checks the status once, at the end. HDF5's own error printing is
!! switched off: failures reach the user only through the caller's message.
!!
!! Reading never trusts the file: every reader first checks the stored type class and
!! shape against what it reads into (a real dataset is a floating-point one, an attribute
!! holds one value, a string is a scalar fixed-length one), so a forged or foreign file
!! is a failure with the object named, never a buffer overrun. `describe` tells a caller
!! the class and shape of an object, to check them against what it expects.
!!
!! String attributes are variable-length UTF-8 (h5py reads them as `str`); string
!! datasets are fixed-length.
module h5io
  use kinds, only: wp
  use errors, only: error_t, ERR_IO
  use, intrinsic :: iso_c_binding, only: c_ptr, c_loc, c_null_ptr, c_char, c_null_char
  use hdf5, only: hid_t, hsize_t, size_t, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, H5S_SCALAR_F, &
                  H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_FORTRAN_S1, H5T_C_S1, H5T_CSET_UTF8_F, &
                  H5T_STR_NULLTERM_F, H5T_INTEGER_F, H5T_FLOAT_F, H5T_STRING_F, &
                  h5tset_cset_f, h5tset_strpad_f, h5tget_class_f, h5tis_variable_str_f, &
                  h5aget_space_f, h5aget_type_f, h5lexists_f, h5aexists_f, &
                  h5open_f, h5dont_atexit_f, h5eset_auto_f, h5fcreate_f, h5fopen_f, h5fclose_f, &
                  h5gcreate_f, h5gopen_f, h5gclose_f, h5iget_name_f, h5screate_f, &
                  h5screate_simple_f, h5sclose_f, h5sget_simple_extent_ndims_f, &
                  h5sget_simple_extent_dims_f, h5dcreate_f, h5dopen_f, h5dclose_f, h5dwrite_f, &
                  h5dread_f, h5dget_space_f, h5dget_type_f, h5acreate_f, h5aopen_f, h5aclose_f, &
                  h5awrite_f, h5aread_f, h5tcopy_f, h5tset_size_f, h5tget_size_f, h5tclose_f, &
                  haddr_t, h5pcreate_f, h5pset_alloc_time_f, h5pset_fill_time_f, h5pset_obj_track_times_f, &
                  h5dget_offset_f, H5P_DATASET_CREATE_F, H5P_GROUP_CREATE_F, H5D_ALLOC_TIME_EARLY_F, &
                  H5D_FILL_TIME_NEVER_F, H5P_FILE_ACCESS_F, h5pset_libver_bounds_f, H5F_LIBVER_LATEST_F, &
                  H5P_DEFAULT_F, h5pclose_f
  implicit none (type, external)
  private

  public :: file_open, file_close, group_open, group_close
  public :: write_dset, write_attr, write_attr_list, read_dset, read_attr, describe, exists, reserve_dset

  integer, parameter, public :: CLASS_OTHER = 0     !< a type class the files do not use
  integer, parameter, public :: CLASS_INTEGER = 1   !< integer numbers
  integer, parameter, public :: CLASS_REAL = 2      !< floating-point numbers
  integer, parameter, public :: CLASS_STRING = 3    !< fixed-length string
  integer, parameter, public :: CLASS_VSTRING = 4   !< variable-length string

  !> Write a dataset: a real or integer array of any rank, a real or integer scalar, or
  !! a string.
  interface write_dset
    module procedure dset_real, dset_int, dset_text
  end interface write_dset

  !> Read a dataset into an allocatable: real of rank 1 or 2, integer of rank 1, or a
  !! scalar string.
  interface read_dset
    module procedure read_real, read_int, read_str
  end interface read_dset

  integer(hsize_t), parameter :: SCALAR(0) = [integer(hsize_t) ::]   ! the shape of a scalar
  logical, save :: initialised = .false.
  ! creation properties of every dataset and group written: no modification times (the
  ! same result gives the same bytes, and each object header is smaller); `reserved`: the
  ! storage allocated at creation and never filled (reserve_dset)
  integer(hid_t), save :: dcpl_plain = -1, dcpl_reserved = -1, gcpl_plain = -1

contains

  ! ---- files and groups ---------------------------------------------------------------

  !> Open the HDF5 file `path` for reading, or create (truncate) it for writing when
  !! `create` is present and true; fid = -1 on failure.
  subroutine file_open(path, fid, st, create, checksums)
    character(len=*), intent(in) :: path        !< file path
    integer(hid_t), intent(out) :: fid          !< the open file
    type(error_t), intent(inout) :: st      !< status
    logical, intent(in), optional :: create     !< create the file (default: read it)
    !> create it in the latest file format, whose metadata (superblock, object headers, heaps,
    !! B-trees) carry checksums that HDF5 verifies on reading: a file corrupted there fails
    !! to open or to read, where the default format's parser can crash (SIGSEGV) on it
    !! (HDF5 1.10 readers; the checkpoint; default .false.)
    logical, intent(in), optional :: checksums
    logical :: new
    integer :: e, ec
    integer(hid_t) :: fapl
    fid = -1
    new = .false.
    if (present(create)) new = create
    call library_init(st)
    if (st%failed()) return
    fapl = H5P_DEFAULT_F
    if (new .and. present(checksums)) then
      if (checksums) then
        call h5pcreate_f(H5P_FILE_ACCESS_F, fapl, e)
        if (e == 0) call h5pset_libver_bounds_f(fapl, H5F_LIBVER_LATEST_F, H5F_LIBVER_LATEST_F, e)
        if (e /= 0) then
          if (fapl /= H5P_DEFAULT_F) call h5pclose_f(fapl, ec)
          call fail(st, 'failed to make the file access properties of '//path)
          return
        end if
      end if
    end if
    if (new) then
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, fid, e, access_prp=fapl)
    else
      call h5fopen_f(path, H5F_ACC_RDONLY_F, fid, e)
    end if
    if (fapl /= H5P_DEFAULT_F) call h5pclose_f(fapl, ec)
    if (e /= 0) then
      fid = -1
      call fail(st, merge('failed to create ', 'failed to open   ', new)//path)
    end if
  end subroutine file_open

  !> Close a file (whatever the status: this releases it); closing flushes the data, so a
  !! full disk may show only here. Nothing happens for fid < 0.
  subroutine file_close(fid, st)
    integer(hid_t), intent(inout) :: fid        !< the file; -1 on return
    type(error_t), intent(inout) :: st      !< status
    integer :: e
    if (fid < 0) return
    call h5fclose_f(fid, e)
    if (e /= 0) call fail(st, 'failed to close the file (writing out its buffers)')
    fid = -1
  end subroutine file_close

  !> Open the group `name` of `loc`, or create it when `create` is present and true;
  !! gid = -1 if that fails or the status is already set.
  subroutine group_open(loc, name, gid, st, create)
    integer(hid_t), intent(in) :: loc           !< file or group
    character(len=*), intent(in) :: name        !< group name
    integer(hid_t), intent(out) :: gid          !< the open group
    type(error_t), intent(inout) :: st      !< status
    logical, intent(in), optional :: create     !< create the group (default: open it)
    logical :: new
    integer :: e
    gid = -1
    if (st%failed()) return
    new = .false.
    if (present(create)) new = create
    if (new) then
      call h5gcreate_f(loc, name, gid, e, gcpl_id=gcpl_plain)
    else
      call h5gopen_f(loc, name, gid, e)
    end if
    if (e /= 0) then
      gid = -1
      call fail(st, merge('failed to create group', 'failed to open group  ', new), loc, name)
    end if
  end subroutine group_open

  !> Close a group (whatever the status). Nothing happens for gid < 0.
  subroutine group_close(gid, st)
    integer(hid_t), intent(inout) :: gid        !< the group; -1 on return
    type(error_t), intent(inout) :: st      !< status
    integer :: e
    if (gid < 0) return
    call h5gclose_f(gid, e)
    if (e /= 0) call fail(st, 'failed to close group', gid, '')
    gid = -1
  end subroutine group_close

  ! ---- writing --------------------------------------------------------------------------

  !> Write a real array of any rank (or a scalar) as the dataset `name` of `loc`; an
  !! (n1, n2) array shows as (n2, n1) in h5py. With `units`, the dataset gets the string
  !! attribute `units` (such as 'm', 'N/m', '1').
  subroutine dset_real(loc, name, v, st, units)
    real(wp), intent(in), target, contiguous :: v(..)       !< the data
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    type(error_t), intent(inout) :: st                  !< status
    character(len=*), intent(in), optional :: units         !< unit of the values
    call put_data(loc, name, H5T_NATIVE_DOUBLE, v, st, units)
  end subroutine dset_real

  !> Write an integer array of any rank (or a scalar) as the dataset `name` of `loc`,
  !! with the attribute `units` when given.
  subroutine dset_int(loc, name, v, st, units)
    integer, intent(in), target, contiguous :: v(..)        !< the data
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    type(error_t), intent(inout) :: st                  !< status
    character(len=*), intent(in), optional :: units         !< unit of the values
    call put_data(loc, name, H5T_NATIVE_INTEGER, v, st, units)
  end subroutine dset_int

  !> A numeric dataset of memory type `mtype` from contiguous data of any rank.
  subroutine put_data(loc, name, mtype, v, st, units)
    integer(hid_t), intent(in) :: loc, mtype
    character(len=*), intent(in) :: name
    type(*), intent(in), target, contiguous :: v(..)
    type(error_t), intent(inout) :: st
    character(len=*), intent(in), optional :: units
    type(c_ptr) :: p
    p = c_null_ptr
    if (size(v) > 0) p = c_loc(v)
    call put(loc, name, .false., mtype, shape(v, kind=hsize_t), p, st, units)
  end subroutine put_data

  !> Write a string as the scalar dataset `name` of `loc`.
  subroutine dset_text(loc, name, s, st)
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    character(len=*), intent(in) :: s                       !< the text
    type(error_t), intent(inout) :: st                  !< status
    call put_string(loc, name, .false., s, st)
  end subroutine dset_text

  !> Write the scalar attribute `name` of `loc`: real, integer or string.
  subroutine write_attr(loc, name, v, st)
    integer(hid_t), intent(in) :: loc                   !< file, group or dataset
    character(len=*), intent(in) :: name                !< attribute name
    class(*), intent(in), target :: v                   !< its value
    type(error_t), intent(inout) :: st              !< status
    select type (v)
    type is (real(wp))
      call put(loc, name, .true., H5T_NATIVE_DOUBLE, SCALAR, c_loc(v), st)
    type is (integer)
      call put(loc, name, .true., H5T_NATIVE_INTEGER, SCALAR, c_loc(v), st)
    type is (character(*))
      call put_string(loc, name, .true., v, st)
    class default
      call fail(st, 'cannot write this type as', loc, name)
    end select
  end subroutine write_attr

  !> Write the rank-1 attribute `name` of `loc`: an integer list such as the ids of
  !! the bodies of a contact pair.
  subroutine write_attr_list(loc, name, v, st)
    integer(hid_t), intent(in) :: loc                   !< file, group or dataset
    character(len=*), intent(in) :: name                !< attribute name
    integer, intent(in), target, contiguous :: v(:)     !< its values
    type(error_t), intent(inout) :: st                  !< status
    call put(loc, name, .true., H5T_NATIVE_INTEGER, [size(v, kind=hsize_t)], c_loc(v), st)
  end subroutine write_attr_list

  !> A scalar string: an attribute as a variable-length UTF-8 string (h5py reads `str`),
  !! a dataset as a fixed-length one (Fortran, space padded; an empty one is stored as ' ').
  recursive subroutine put_string(loc, name, attr, s, st)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name, s
    logical, intent(in) :: attr
    type(error_t), intent(inout) :: st
    character(kind=c_char), allocatable, target :: c(:)
    type(c_ptr), target :: pv(1)
    integer(hid_t) :: ty
    integer :: n, e, ec
    if (st%failed()) return
    if (attr) then
      n = len(s) + 1
      c = transfer(s//c_null_char, 'a', n)
      pv(1) = c_loc(c)
      call h5tcopy_f(H5T_C_S1, ty, e)
    else
      n = max(1, len(s))
      c = transfer(s//' ', 'a', n)
      call h5tcopy_f(H5T_FORTRAN_S1, ty, e)
    end if
    if (e /= 0) then
      call fail(st, 'failed to make the string type of', loc, name)
      return
    end if
    if (attr) then
      ! H5T_VARIABLE is (size_t)-1, which the Fortran library passes on as it is
      call h5tset_size_f(ty, -1_size_t, e)
      if (e == 0) call h5tset_strpad_f(ty, H5T_STR_NULLTERM_F, e)
      if (e == 0) call h5tset_cset_f(ty, H5T_CSET_UTF8_F, e)
    else
      call h5tset_size_f(ty, int(n, size_t), e)
    end if
    if (e /= 0) call fail(st, 'failed to make the string type of', loc, name)
    if (attr) then
      call put(loc, name, attr, ty, SCALAR, c_loc(pv), st)
    else
      call put(loc, name, attr, ty, SCALAR, c_loc(c), st)
    end if
    call h5tclose_f(ty, ec)
  end subroutine put_string

  !> The one writer: create `name` in `loc` as a dataset, or an attribute when `attr`, of
  !! memory (and file) type `mtype` and shape `dims` (none: scalar), and write the data at
  !! `buf` (not touched when the shape has no element); a dataset gets the attribute
  !! `units` when given.
  recursive subroutine put(loc, name, attr, mtype, dims, buf, st, units)
    integer(hid_t), intent(in) :: loc, mtype
    character(len=*), intent(in) :: name
    logical, intent(in) :: attr
    integer(hsize_t), intent(in) :: dims(:)
    type(c_ptr), intent(in) :: buf
    type(error_t), intent(inout) :: st
    character(len=*), intent(in), optional :: units
    integer(hid_t) :: sp, obj
    integer :: e, ec
    if (st%failed()) return
    if (size(dims) == 0) then
      call h5screate_f(H5S_SCALAR_F, sp, e)
    else
      call h5screate_simple_f(size(dims), dims, sp, e)
    end if
    if (e /= 0) then
      call fail(st, 'failed to make the dataspace of', loc, name)
      return
    end if
    if (attr) then
      call h5acreate_f(loc, name, mtype, sp, obj, e)
    else
      call h5dcreate_f(loc, name, mtype, sp, obj, e, dcpl_id=dcpl_plain)
    end if
    if (e /= 0) then
      call fail(st, 'failed to create '//kind_name(attr), loc, name)
    else
      if (product(dims) > 0) then
        if (attr) then
          call h5awrite_f(obj, mtype, buf, e)
        else
          call h5dwrite_f(obj, mtype, buf, e)
        end if
        if (e /= 0) call fail(st, 'failed to write '//kind_name(attr), loc, name)
      end if
      if (present(units) .and. .not. attr) call put_string(obj, 'units', .true., units, st)
      call close_object(attr, obj, loc, name, st)
    end if
    call h5sclose_f(sp, ec)
  end subroutine put

  !> Create the dataset `name` of `loc`, real (or integer when `int_data`) of shape dims
  !! (at least one element), with its storage allocated now and not written, and the
  !! attribute `units` when given: offset is where its data start in the file, for the
  !! caller to write them there in the memory's layout and byte order (the file type is
  !! the native one), all of them before the file is used. -1 on failure.
  subroutine reserve_dset(loc, name, dims, int_data, offset, st, units)
    integer(hid_t), intent(in) :: loc                   !< file or group
    character(len=*), intent(in) :: name                !< dataset name
    integer(hsize_t), intent(in) :: dims(:)             !< its shape (Fortran order)
    logical, intent(in) :: int_data                     !< integers (else reals)
    integer(haddr_t), intent(out) :: offset             !< byte offset of its data
    type(error_t), intent(inout) :: st                  !< status
    character(len=*), intent(in), optional :: units     !< unit of the values
    integer(hid_t) :: sp, obj, ty
    integer :: e, ec
    offset = -1
    if (st%failed()) return
    if (product(dims) < 1) then
      call fail(st, 'no data to reserve for dataset', loc, name)
      return
    end if
    ty = merge(H5T_NATIVE_INTEGER, H5T_NATIVE_DOUBLE, int_data)
    call h5screate_simple_f(size(dims), dims, sp, e)
    if (e /= 0) then
      call fail(st, 'failed to make the dataspace of', loc, name)
      return
    end if
    call h5dcreate_f(loc, name, ty, sp, obj, e, dcpl_id=dcpl_reserved)
    if (e /= 0) then
      call fail(st, 'failed to create dataset', loc, name)
    else
      call h5dget_offset_f(obj, offset, e)
      if (e /= 0 .or. offset < 0) then
        offset = -1
        call fail(st, 'failed to allocate the storage of dataset', loc, name)
      end if
      if (present(units)) call put_string(obj, 'units', .true., units, st)
      call close_object(.false., obj, loc, name, st)
    end if
    call h5sclose_f(sp, ec)
    if (st%failed()) offset = -1
  end subroutine reserve_dset

  ! ---- reading --------------------------------------------------------------------------

  !> Whether the dataset (or group), or the attribute when `attr`, `name` of `loc` exists.
  logical function exists(loc, name, attr)
    integer(hid_t), intent(in) :: loc                   !< file, group or dataset
    character(len=*), intent(in) :: name                !< its name
    logical, intent(in) :: attr                         !< an attribute (else a dataset or group)
    integer :: e
    exists = .false.
    if (attr) then
      call h5aexists_f(loc, name, exists, e)
    else
      call h5lexists_f(loc, name, exists, e)
    end if
    if (e /= 0) exists = .false.
  end function exists

  !> The type class (CLASS_*) and the shape of the dataset, or of the attribute when
  !! `attr`, `name` of `loc`, without reading it. dims is in Fortran order (h5py shows it
  !! reversed), of size 0 for a scalar. A failure when the object cannot be opened.
  subroutine describe(loc, name, attr, cls, dims, st)
    integer(hid_t), intent(in) :: loc                       !< file, group or dataset
    character(len=*), intent(in) :: name                    !< object name
    logical, intent(in) :: attr                             !< an attribute (else a dataset)
    integer, intent(out) :: cls                             !< CLASS_*
    integer(hsize_t), allocatable, intent(out) :: dims(:)   !< stored shape
    type(error_t), intent(inout) :: st                  !< status
    integer(hid_t) :: obj, ty, sp
    integer(hsize_t), allocatable :: maxd(:)
    integer :: e, ec, r, tc
    logical :: vl
    cls = CLASS_OTHER
    allocate (dims(0))
    if (st%failed()) return
    if (attr) then
      call h5aopen_f(loc, name, obj, e)
    else
      call h5dopen_f(loc, name, obj, e)
    end if
    if (e /= 0) then
      call fail(st, 'failed to open '//kind_name(attr), loc, name)
      return
    end if
    if (attr) then
      call h5aget_type_f(obj, ty, e)
    else
      call h5dget_type_f(obj, ty, e)
    end if
    if (e == 0) then
      call h5tget_class_f(ty, tc, e)
      if (e == 0) then
        if (tc == H5T_INTEGER_F) then
          cls = CLASS_INTEGER
        else if (tc == H5T_FLOAT_F) then
          cls = CLASS_REAL
        else if (tc == H5T_STRING_F) then
          call h5tis_variable_str_f(ty, vl, e)
          cls = merge(CLASS_VSTRING, CLASS_STRING, vl)
        end if
      end if
      call h5tclose_f(ty, ec)
    end if
    r = -1
    if (e == 0) then
      if (attr) then
        call h5aget_space_f(obj, sp, e)
      else
        call h5dget_space_f(obj, sp, e)
      end if
      if (e == 0) then
        call h5sget_simple_extent_ndims_f(sp, r, e)
        ! this call returns the rank (not 0) in its error argument on success
        if (e >= 0 .and. r >= 0) then
          deallocate (dims)
          allocate (dims(r), maxd(r))
          e = 0
          if (r > 0) call h5sget_simple_extent_dims_f(sp, dims, maxd, e)
        end if
        call h5sclose_f(sp, ec)
      end if
    end if
    if (e < 0 .or. r < 0) call fail(st, 'failed to read the type and shape of '//kind_name(attr), loc, name)
    call close_object(attr, obj, loc, name, st)
  end subroutine describe

  !> Read a real dataset of rank 1 or 2 into v, allocated to the stored shape.
  subroutine read_real(loc, name, v, st)
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    real(wp), allocatable, target, intent(out) :: v(..)     !< the data
    type(error_t), intent(inout) :: st                  !< status
    integer(hsize_t) :: d(2)
    if (rank(v) > 2) call fail(st, 'cannot read an array of rank above 2 from dataset', loc, name)
    if (st%failed()) return
    call extent(loc, name, CLASS_REAL, d(1:rank(v)), st)
    if (st%failed()) return
    select rank (v)
    rank (1)
      allocate (v(d(1)))
    rank (2)
      allocate (v(d(1), d(2)))
    end select
    if (size(v) > 0) call get(loc, name, .false., H5T_NATIVE_DOUBLE, c_loc(v), st)
  end subroutine read_real

  !> Read an integer dataset of rank 1 into v, allocated to the stored size.
  subroutine read_int(loc, name, v, st)
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    integer, allocatable, target, intent(out) :: v(:)       !< the data
    type(error_t), intent(inout) :: st                  !< status
    integer(hsize_t) :: d(1)
    call extent(loc, name, CLASS_INTEGER, d, st)
    if (st%failed()) return
    allocate (v(d(1)))
    if (d(1) > 0) call get(loc, name, .false., H5T_NATIVE_INTEGER, c_loc(v), st)
  end subroutine read_int

  !> Read a scalar fixed-length string dataset into s (its stored length).
  subroutine read_str(loc, name, s, st)
    integer(hid_t), intent(in) :: loc                       !< file or group
    character(len=*), intent(in) :: name                    !< dataset name
    character(len=:), allocatable, intent(out) :: s         !< the text
    type(error_t), intent(inout) :: st                  !< status
    character(kind=c_char), allocatable, target :: c(:)
    integer(hsize_t), allocatable :: dims(:)
    integer(hid_t) :: ds, ty
    integer(size_t) :: n
    integer :: e, ec, cls
    s = ''
    call describe(loc, name, .false., cls, dims, st)
    if (st%failed()) return
    if (cls /= CLASS_STRING .or. size(dims) /= 0) then
      call fail(st, 'not a scalar fixed-length string:', loc, name)
      return
    end if
    call h5dopen_f(loc, name, ds, e)
    if (e /= 0) then
      call fail(st, 'failed to open dataset', loc, name)
      return
    end if
    call h5dget_type_f(ds, ty, e)
    call h5dclose_f(ds, ec)
    n = 0
    if (e == 0) call h5tget_size_f(ty, n, e)
    if (e /= 0 .or. n < 1) then
      call fail(st, 'failed to read the string type of dataset', loc, name)
    else
      allocate (c(n))
      call get(loc, name, .false., ty, c_loc(c), st)
      s = transfer(c, repeat(' ', int(n)))
    end if
    if (e == 0) call h5tclose_f(ty, ec)
  end subroutine read_str

  !> Read the scalar attribute `name` of `loc` into v (real or integer); a failure unless
  !! the attribute holds one number of that class.
  subroutine read_attr(loc, name, v, st)
    integer(hid_t), intent(in) :: loc                   !< file, group or dataset
    character(len=*), intent(in) :: name                !< attribute name
    class(*), intent(inout), target :: v                !< receives the value
    type(error_t), intent(inout) :: st              !< status
    integer(hsize_t), allocatable :: dims(:)
    integer :: cls, want
    select type (v)
    type is (real(wp))
      want = CLASS_REAL
    type is (integer)
      want = CLASS_INTEGER
    class default
      call fail(st, 'cannot read this type from attribute', loc, name)
      return
    end select
    call describe(loc, name, .true., cls, dims, st)
    if (st%failed()) return
    if (cls /= want .or. product(dims) /= 1) then
      call fail(st, 'not a single '//merge('real   ', 'integer', want == CLASS_REAL)//' value: attribute', loc, name)
      return
    end if
    select type (v)
    type is (real(wp))
      call get(loc, name, .true., H5T_NATIVE_DOUBLE, c_loc(v), st)
    type is (integer)
      call get(loc, name, .true., H5T_NATIVE_INTEGER, c_loc(v), st)
    end select
  end subroutine read_attr

  !> The one reader: read the dataset, or the attribute when `attr`, `name` of `loc` as
  !! memory type `mtype` into the memory at `buf` (allocated by the caller to the size
  !! the caller has checked).
  subroutine get(loc, name, attr, mtype, buf, st)
    integer(hid_t), intent(in) :: loc, mtype
    character(len=*), intent(in) :: name
    logical, intent(in) :: attr
    type(c_ptr), intent(in) :: buf
    type(error_t), intent(inout) :: st
    integer(hid_t) :: obj
    type(c_ptr) :: p
    integer :: e, eo
    if (st%failed()) return
    p = buf   ! HDF5 declares the buffer intent(inout)
    if (attr) then
      call h5aopen_f(loc, name, obj, eo)
      if (eo == 0) call h5aread_f(obj, mtype, p, e)
    else
      call h5dopen_f(loc, name, obj, eo)
      if (eo == 0) call h5dread_f(obj, mtype, p, e)
    end if
    if (eo /= 0) e = eo
    if (e /= 0) call fail(st, 'failed to read '//kind_name(attr), loc, name)
    if (eo == 0) call close_object(attr, obj, loc, name, st)
  end subroutine get

  !> The stored shape of dataset `name`; a failure when its rank is not size(dims) or its
  !! class is not `cls`.
  subroutine extent(loc, name, cls, dims, st)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    integer, intent(in) :: cls
    integer(hsize_t), intent(out) :: dims(:)
    type(error_t), intent(inout) :: st
    integer(hsize_t), allocatable :: d(:)
    integer :: c
    dims = 0
    call describe(loc, name, .false., c, d, st)
    if (st%failed()) return
    if (c /= cls) then
      call fail(st, 'dataset does not hold '//merge('real numbers', 'integers    ', cls == CLASS_REAL)//':', loc, name)
    else if (size(d) /= size(dims)) then
      call fail(st, 'dataset does not have the expected rank:', loc, name)
    else
      dims = d
    end if
  end subroutine extent

  ! ---- support ------------------------------------------------------------------------

  !> Open the library once, with no HDF5 clean-up at exit (a file whose flush failed would
  !! make it loop; every file is closed explicitly); and no HDF5 error printing on the
  !! calling thread, at every call: a thread-safe HDF5 keeps that setting per thread, and
  !! the result file may be written from another thread than the one that opened the library.
  subroutine library_init(st)
    type(error_t), intent(inout) :: st
    integer :: e
    if (.not. initialised) then
      call h5dont_atexit_f(e)
      call h5open_f(e)
      if (e /= 0) then
        call fail(st, 'failed to initialise the HDF5 library')
        return
      end if
      call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl_plain, e)
      if (e == 0) call h5pset_obj_track_times_f(dcpl_plain, .false., e)
      if (e == 0) call h5pcreate_f(H5P_DATASET_CREATE_F, dcpl_reserved, e)
      if (e == 0) call h5pset_obj_track_times_f(dcpl_reserved, .false., e)
      if (e == 0) call h5pset_alloc_time_f(dcpl_reserved, H5D_ALLOC_TIME_EARLY_F, e)
      if (e == 0) call h5pset_fill_time_f(dcpl_reserved, H5D_FILL_TIME_NEVER_F, e)
      if (e == 0) call h5pcreate_f(H5P_GROUP_CREATE_F, gcpl_plain, e)
      if (e == 0) call h5pset_obj_track_times_f(gcpl_plain, .false., e)
      if (e /= 0) then
        call fail(st, 'failed to make the HDF5 creation properties')
        return
      end if
      initialised = .true.
    end if
    call h5eset_auto_f(0, e)
  end subroutine library_init

  subroutine close_object(attr, obj, loc, name, st)
    logical, intent(in) :: attr
    integer(hid_t), intent(in) :: obj, loc
    character(len=*), intent(in) :: name
    type(error_t), intent(inout) :: st
    integer :: e
    if (attr) then
      call h5aclose_f(obj, e)
    else
      call h5dclose_f(obj, e)
    end if
    if (e /= 0) call fail(st, 'failed to close '//kind_name(attr), loc, name)
  end subroutine close_object

  pure function kind_name(attr) result(k)
    logical, intent(in) :: attr
    character(len=:), allocatable :: k
    k = merge('attribute', 'dataset  ', attr)
    k = trim(k)
  end function kind_name

  !> Record the first failure: `text`, followed by the path of `name` in `loc` if given.
  subroutine fail(st, text, loc, name)
    type(error_t), intent(inout) :: st
    character(len=*), intent(in) :: text
    integer(hid_t), intent(in), optional :: loc
    character(len=*), intent(in), optional :: name
    if (st%failed()) return
    if (present(loc) .and. present(name)) then
      call st%set(ERR_IO, trim(text)//' '//object_path(loc, name))
    else
      call st%set(ERR_IO, trim(text))
    end if
  end subroutine fail

  !> The path of `name` in the object `loc` ('/contact/gap'), for messages.
  function object_path(loc, name) result(p)
    integer(hid_t), intent(in) :: loc
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: p
    character(len=1024) :: buf
    integer(size_t) :: n
    integer :: e
    buf = ''
    call h5iget_name_f(loc, buf, int(len(buf), size_t), n, e)
    p = trim(buf)
    if (e /= 0) p = ''
    if (len(name) == 0) return
    if (len(p) == 0) then
      p = name
    else if (p(len(p):len(p)) == '/') then
      p = p//name
    else
      p = p//'/'//name
    end if
  end function object_path

end module h5io
