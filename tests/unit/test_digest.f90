!> Tests of module digest: FNV-1a 64 against the published test vectors, a file's hash
!! equal to its text's, a one-byte change seen, a missing file an error.
program test_digest
  use digest, only: file_digest, text_digest
  use, intrinsic :: iso_fortran_env, only: int8
  use errors, only: error_t
  use testing, only: report, test_summary, scratch_path, fresh_folder
  implicit none (type, external)
  character(len=:), allocatable :: dir
  character(len=16) :: h1, h2
  character(len=3000) :: big
  type(error_t) :: err
  integer :: u, i

  ! published FNV-1a 64 vectors (http://www.isthe.com/chongo/src/fnv/test_fnv.c)
  call report(text_digest('') == 'cbf29ce484222325', 'FNV-1a 64 of "" (got '//text_digest('')//')')
  call report(text_digest('a') == 'af63dc4c8601ec8c', 'FNV-1a 64 of "a" (got '//text_digest('a')//')')
  call report(text_digest('foobar') == '85944171f73967e8', 'FNV-1a 64 of "foobar" (got '//text_digest('foobar')//')')
  call report(text_digest(transfer([-1_int8, -127_int8 - 1_int8], 'ab')) /= text_digest(achar(127)//achar(0)), &
              'bytes above 127 hash apart from their low seven bits')

  ! the files in build/<kind>/test-digest (beside the folder of this program): a release
  ! and a checked make check running at once share none
  dir = scratch_path('test-digest')
  call fresh_folder(dir)
  do i = 1, len(big)
    big(i:i) = achar(32 + mod(7*i, 90))
  end do
  open (newunit=u, file=dir//'/a.msh', access='stream', form='unformatted', status='replace')
  write (u) big
  close (u)
  call file_digest(dir//'/a.msh', h1, err)
  call report(.not. err%failed() .and. h1 == text_digest(big), 'a file hashes as its bytes ('//h1//')')
  big(1500:1500) = achar(iachar(big(1500:1500)) + 1)
  open (newunit=u, file=dir//'/a.msh', access='stream', form='unformatted', status='replace')
  write (u) big
  close (u)
  call file_digest(dir//'/a.msh', h2, err)
  call report(.not. err%failed() .and. h2 /= h1, 'one byte changed, another hash ('//h2//')')
  call file_digest(dir//'/missing.msh', h2, err)
  call report(err%failed() .and. index(err%text(), 'missing.msh') > 0, 'a missing file: an error naming it ('// &
              err%text()//')')
  call test_summary()
end program test_digest
