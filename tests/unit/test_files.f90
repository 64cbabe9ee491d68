!> Tests of module files: unique temporary names, and commit_files committing a set of
!! files all or nothing (success; a final name that is a folder; a rename that fails
!! half-way, which must put every earlier file back; no temporary or kept-aside file
!! left in any case).
program test_files
  use files, only: temp_name, run_id, commit_files, write_text, remove_file, dir_name
  use errors, only: error_t, ERR_IO
  use testing, only: report, test_summary, scratch_path, fresh_folder
  implicit none (type, external)
  character(len=:), allocatable :: dir
  character(len=512) :: fin(3)
  character(len=640) :: tmp(3)
  character(len=:), allocatable :: t1, t2
  type(error_t) :: err
  integer :: k, rc

  ! the files in build/<kind>/test-files (beside the folder of this program): a release
  ! and a checked make check running at once share none
  dir = scratch_path('test-files')
  call fresh_folder(dir)
  do k = 1, 3
    write (fin(k), '(a,i0,a)') dir//'/f', k, '.txt'
  end do

  ! ---- temporary names ---------------------------------------------------------------
  t1 = temp_name(fin(1))
  t2 = temp_name(fin(1))
  call report(t1 /= t2, 'temp_name: two calls give two names ('//t1//', '//t2//')')
  call report(index(t1, trim(fin(1))//'.') == 1 .and. t1(len(t1) - 3:) == '.tmp', &
              'temp_name: <file>.<host>.<pid>.<n>.tmp, in the folder of the file')
  call report(index(run_id(), '.') > 0 .and. run_id() == run_id(), 'run_id: host.pid.time, fixed')
  call report(dir_name('a/b/x.h5') == 'a/b' .and. dir_name('x.h5') == '.' .and. dir_name('/x.h5') == '/', &
              'dir_name')

  ! ---- 1. new files, nothing there before ----------------------------------------------
  call make_temps('new1')
  call commit_files(tmp, fin, err)
  call report(.not. err%failed() .and. all_are('new1') .and. clean(), 'commit into free names: all renamed, nothing left over')

  ! ---- 2. replace earlier files --------------------------------------------------------
  call make_temps('new2')
  call commit_files(tmp, fin, err)
  call report(.not. err%failed() .and. all_are('new2') .and. clean(), 'commit over earlier files: all replaced, none kept aside')

  ! ---- 3. a final name is a folder: nothing replaced --------------------------------------
  call make_temps('new3')
  call remove_file(fin(2))
  call execute_command_line('mkdir '//trim(fin(2)), exitstat=rc)
  call commit_files(tmp, fin, err)
  call report(err%category == ERR_IO .and. index(err%text(), trim(fin(2))//' is a folder') > 0 .and. &
              index(err%text(), 'nothing was replaced') > 0, 'a folder at a final name: failure naming it ('//err%text()//')')
  call report(content(fin(1)) == 'new2' .and. content(fin(3)) == 'new2' .and. clean(), &
              'a folder at a final name: the other files unchanged, no temporary left')
  call execute_command_line('rmdir '//trim(fin(2)), exitstat=rc)

  ! ---- 4. the third rename fails (its temporary file is missing): roll back -------------
  call make_temps('new4')
  call write_text(fin(2), 'new2', err)
  call report(.not. err%failed(), 'write_text')
  call remove_file(tmp(3))
  call commit_files(tmp, fin, err)
  call report(err%category == ERR_IO .and. index(err%text(), 'cannot rename') > 0 .and. index(err%text(), 'put back') > 0, &
              'a rename failing half-way: failure ('//err%text()//')')
  call report(all_are('new2') .and. clean(), &
              'a rename failing half-way: the earlier files are all back, no temporary or kept file left')

  ! ---- 5. the same with no earlier file at the first name: it is removed again ----------
  call remove_file(fin(1))
  call make_temps('new5')
  call remove_file(tmp(3))
  call commit_files(tmp, fin, err)
  block
    logical :: there
    inquire (file=fin(1), exist=there)
    call report(err%failed() .and. .not. there .and. content(fin(2)) == 'new2' .and. content(fin(3)) == 'new2' &
                .and. clean(), 'a rename failing half-way: a name that was free is free again')
  end block

  call test_summary()

contains

  subroutine make_temps(text)
    character(len=*), intent(in) :: text
    integer :: j
    type(error_t) :: w
    do j = 1, 3
      tmp(j) = temp_name(fin(j))
      call write_text(tmp(j), text, w)
    end do
  end subroutine make_temps

  function content(path) result(t)
    character(len=*), intent(in) :: path
    character(len=:), allocatable :: t
    character(len=64) :: buf
    integer :: u, ios
    t = '<none>'
    open (newunit=u, file=path, status='old', access='stream', form='unformatted', action='read', iostat=ios)
    if (ios /= 0) return
    buf = ''
    read (u, iostat=ios) buf
    close (u)
    t = trim(buf)
  end function content

  logical function all_are(text)
    character(len=*), intent(in) :: text
    integer :: j
    all_are = .true.
    do j = 1, 3
      all_are = all_are .and. content(fin(j)) == text
    end do
  end function all_are

  !> No .tmp or .bak file in the folder.
  logical function clean()
    integer :: r
    call execute_command_line('ls -A '//dir//' | grep -q -E "\.(tmp|bak)$"', exitstat=r)
    clean = r /= 0
  end function clean

end program test_files
