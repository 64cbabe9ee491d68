!> The names a result gives its bodies and files hold any number of bodies and pairs: the
!! HDF5 group of body 10000 is 'body10000' (a fixed 8-character name could not hold it and
!! stopped the run with a runtime error), and the XDMF companions of 10,001 bodies and
!! 10,000 pairs are <stem>_body1 .. _body10001.xdmf and <stem>_contact1 .. _contact10000.xdmf.
program test_result_names
  use results, only: body_group_name, result_files
  use testing, only: report, test_summary
  implicit none (type, external)
  character(len=64), allocatable :: name(:)

  call report(body_group_name(7) == 'body7', 'body_group_name(7) = body7')
  call report(body_group_name(10000) == 'body10000', 'body_group_name(10000) = body10000 ('// &
              body_group_name(10000)//')')
  call report(body_group_name(123456789) == 'body123456789', 'body_group_name(123456789) = body123456789')
  call result_files('out/r.h5', 10001, 10000, name)
  call report(size(name) == 3 + 10001 + 10000, 'result_files: the .h5, .xdmf, 10001 body files, the contact '// &
              'file and 10000 pair files')
  call report(name(1) == 'out/r.h5' .and. name(2) == 'out/r.xdmf', 'result_files: the .h5 and its .xdmf')
  call report(name(2 + 10000) == 'out/r_body10000.xdmf' .and. name(2 + 10001) == 'out/r_body10001.xdmf', &
              'result_files: out/r_body10000.xdmf, out/r_body10001.xdmf ('//trim(name(2 + 10000))//')')
  call report(name(3 + 10001) == 'out/r_contact.xdmf' .and. name(3 + 10001 + 10000) == 'out/r_contact10000.xdmf', &
              'result_files: out/r_contact.xdmf, out/r_contact10000.xdmf')
  call test_summary()
end program test_result_names
