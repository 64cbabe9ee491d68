!> Tests of budget%body_rank_map and rank_memory_mb (the MPI binary's bodies on its ranks):
!! two equal bodies split in half with an odd rank to body 1; groups in proportion to the
!! factor estimates (each rank beyond the first of a body went to the body with the
!! largest factor per rank at the time); fewer ranks than bodies: each body on one rank, the largest first to
!! the least loaded rank, worked by hand; a rank's memory estimate counts its own bodies'
!! factors only.
program test_rank_map
  use kinds, only: wp
  use config, only: deck_t, deck_init
  use budget, only: body_rank_map, rank_memory_mb, body_memory_mb
  use strings, only: i2s
  use testing, only: report, test_summary
  implicit none (type, external)
  type(deck_t) :: d
  integer :: a, b
  integer, allocatable :: host(:), group(:)
  real(wp), allocatable :: w(:)
  real(wp) :: nm, total, fs0, fs1
  character(len=:), allocatable :: got
  logical :: ok

  ! two equal bodies
  call deck_init(d, 2, 1)
  allocate (host(2), group(2))
  call body_rank_map(d, 1, host, group)
  call report(all(host == 0) .and. all(group == 1), 'two bodies, 1 rank: both on rank 0')
  call body_rank_map(d, 2, host, group)
  call report(all(host == [0, 1]) .and. all(group == 1), 'two bodies, 2 ranks: one each, body 1 on rank 0')
  call body_rank_map(d, 3, host, group)
  call report(all(host == [0, 2]) .and. all(group == [2, 1]), 'two equal bodies, 3 ranks: the odd one to body 1 '// &
              '(got '//i2s(group(1))//', '//i2s(group(2))//')')
  call body_rank_map(d, 8, host, group)
  call report(all(host == [0, 4]) .and. all(group == 4), 'two equal bodies, 8 ranks: 4 each')

  ! three bodies of different sizes on 11 ranks: proportional groups, consecutive ranks
  call deck_init(d, 3, 2)
  d%body(1)%nx = 64
  d%body(1)%ny = 64
  d%body(2)%nx = 16
  d%body(2)%ny = 16
  d%body(3)%nx = 40
  d%body(3)%ny = 20
  deallocate (host, group)
  allocate (host(3), group(3), w(3))
  do a = 1, 3
    total = body_memory_mb(d%body(a), d%solver%factor, nm, w(a))
  end do
  call body_rank_map(d, 11, host, group)
  got = i2s(group(1))//', '//i2s(group(2))//', '//i2s(group(3))
  call report(sum(group) == 11 .and. all(group >= 1) .and. host(1) == 0 .and. all(host(2:3) == host(1:2) + group(1:2)), &
              '3 bodies, 11 ranks: consecutive groups from rank 0, one rank each at least, all ranks used ('//got//')')
  ok = .true.
  do a = 1, 3
    do b = 1, 3
      ! b's last rank went to the largest factor per rank of the time, w_b/(g_b - 1):
      ! no body has more per rank now
      if (a /= b .and. group(b) > 1) ok = ok .and. w(a)/group(a) <= w(b)/(group(b) - 1)
    end do
  end do
  call report(ok .and. group(1) > group(3) .and. group(3) >= group(2), '3 bodies, 11 ranks: groups in proportion '// &
              'to the factor estimates (got '//got//')')

  ! five bodies on two ranks: by hand, with factors 881k (1), 193k (2, 3), 42k (4, 5):
  ! 1 -> rank 0; 2 -> rank 1; 3 -> rank 1 (193k < 881k); 4, 5 -> rank 1 (386k, 428k < 881k)
  call deck_init(d, 5, 4)
  d%body(:)%nx = [64, 32, 32, 16, 16]
  d%body(:)%ny = [64, 32, 32, 16, 16]
  deallocate (host, group)
  allocate (host(5), group(5))
  call body_rank_map(d, 2, host, group)
  got = ''
  do a = 1, 5
    got = got//' '//i2s(host(a))
  end do
  call report(all(host == [0, 1, 1, 1, 1]) .and. all(group == 1), '5 bodies, 2 ranks: the largest body alone, '// &
              'the four others on rank 1 (hosts'//got//')')
  call body_rank_map(d, 4, host, group)
  got = ''
  do a = 1, 5
    got = got//' '//i2s(host(a))
  end do
  ! 1 -> 0, 2 -> 1, 3 -> 2, 4 -> 3, 5 -> 3 (42k, the least loaded)
  call report(all(host == [0, 1, 2, 3, 3]), '5 bodies, 4 ranks: the two smallest share a rank (hosts'//got//')')

  ! a rank's estimate: its own bodies' factors, not all bodies'
  total = rank_memory_mb(d, 2, 0, fs0)
  total = rank_memory_mb(d, 2, 1, fs1)
  deallocate (w)
  allocate (w(5))
  do a = 1, 5
    total = body_memory_mb(d%body(a), d%solver%factor, nm, w(a))
  end do
  call report(abs(fs0/fs1 - w(1)/sum(w(2:5))) <= 1.0e-12_wp*fs0/fs1, '5 bodies, 2 ranks: rank 0''s factor share '// &
              'over rank 1''s is body 1''s factor over bodies 2-5''', fs0/fs1)
  total = rank_memory_mb(d, 1, 0, fs1)
  call report(fs1 > fs0*(1.0_wp + 0.5_wp*sum(w(2:5))/w(1)), '5 bodies, 1 rank: its factor share holds every body''s', &
              fs1/fs0)
  call test_summary()
end program test_rank_map
