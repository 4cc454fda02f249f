!> A cyclic sector's nonlinear mode (one nodal diameter, a travelling wave) from a legacy
!> Fortran program through the run object (module frirom_run): frf_open on the rows the
!> solver reads (contact DoFs of sector 0 and of the next sector, outputs; no K, M, C),
!> run_to_mode and run_set_nonlinear_mode_cyclic with each harmonic's modes and the linear
!> travelling wave it starts from, then run_start in log10 of the modal amplitude and
!> run_advance a batch of points at a time. The sector's data come from the text file that
!> Python writes (tests/capi_cyclic.py write_case), as for examples/cyclic_mode.c.
!>
!> Build (an installed frirom): gfortran cyclic_mode.f90 $(pkg-config --cflags --libs
!> frirom). Run: cyclic_mode SECTOR.txt. Prints "amplitude omega xi xo..." per point, then
!> "status S NPTS"; stops with code 1 on a failure, with the library's message.
program cyclic_mode
    use frirom_kinds, only: wp, ip
    use frirom_run, only: run_t, run_points, run_start, run_advance, run_close, run_to_mode, &
                          run_set_nonlinear_mode_cyclic, RUN_START_COLD, RUN_GOING
    use frirom_solve, only: frf_settings, frf_open, FRF_CONDENSED
    implicit none
    integer(ip), parameter :: batch = 20
    type(frf_settings) :: s
    type(run_t) :: run
    type(run_points) :: p
    integer(ip) :: sz(9), iset(5), n, nh, nc, ngroup, ng, npar, nw, nout, nm, info, j, u, total
    integer(ip), allocatable :: ginfo(:, :), gr(:), gc(:), outdofs(:)
    real(wp) :: rset(6), range(3)
    real(wp), allocatable :: gv(:), params(:), w0(:), fe(:, :), q0r(:, :), psir(:, :, :, :), &
                             omega(:, :), zeta(:, :)
    character(len=512) :: msg, path

    if (command_argument_count() /= 1) error stop 'usage: cyclic_mode SECTOR.txt'
    call get_command_argument(1, path)
    open (newunit=u, file=trim(path), status='old', action='read')
    read (u, *) sz
    read (u, *) iset
    read (u, *) rset
    read (u, *) range
    n = sz(1)
    nh = sz(2)
    nc = 2*nh + 1
    ngroup = sz(4)
    ng = sz(5)
    npar = sz(6)
    nw = sz(7)
    nout = sz(8)
    nm = sz(9)
    allocate (ginfo(3, ngroup), gr(ng), gc(ng), gv(ng), params(npar), w0(nw), fe(n, nc), &
              outdofs(nout), q0r(2, nm), psir(2, n, nm, nh + 1), omega(nm, nh + 1), &
              zeta(nm, nh + 1))
    read (u, *) ginfo
    read (u, *) gr
    read (u, *) gc
    read (u, *) gv
    read (u, *) params
    read (u, *) w0
    read (u, *) fe
    read (u, *) outdofs
    read (u, *) q0r
    read (u, *) psir
    read (u, *) omega
    read (u, *) zeta
    close (u)

    s%harmonics = int(nh)
    s%samples = int(sz(3))
    s%formulation = FRF_CONDENSED
    s%max_points = int(iset(1))
    s%max_iter = int(iset(2))
    s%batch = int(iset(3))
    s%reuse_jacobian = int(iset(4))
    s%history = int(iset(5))
    s%tol_residual = rset(1)
    s%tol_update = rset(2)
    s%tol_stall = rset(3)
    s%ds = rset(4)
    s%ds_min = rset(5)
    s%ds_max = rset(6)
    msg = ''
    ! no K, M, C: the modes give every receptance; indices in the file are 0-based
    call frf_open(run, n, [integer(ip) ::], [integer(ip) ::], [real(wp) ::], &
                  [integer(ip) ::], [integer(ip) ::], [real(wp) ::], [integer(ip) ::], &
                  [integer(ip) ::], [real(wp) ::], 0.0_wp, 0.0_wp, [real(wp) ::], ginfo, &
                  gr + 1, gc + 1, gv, params, fe, outdofs + 1, s, info, msg, w0=w0)
    call check(info)
    call run_to_mode(run, .true., info, msg)
    call check(info)
    call run_set_nonlinear_mode_cyclic(run, cmplx(q0r(1, :), q0r(2, :), wp), range(1), &
                                       cmplx(psir(1, :, :, :), psir(2, :, :, :), wp), omega, &
                                       zeta, info, msg)
    call check(info)
    call run_start(run, RUN_START_COLD, log10(range(2)), log10(range(3)), info, msg)
    call check(info)
    total = 0
    do while (run%status == RUN_GOING)
        call run_advance(run, batch, p, info, msg)
        call check(info)
        do j = 1, p%npts
            write (*, '(*(es25.17))') 10.0_wp**p%lam(j), range(1)*p%y(run%ny - 1, j), &
                range(1)*p%y(run%ny, j), reshape(p%xo(:, :, j), [nout*nc])
        end do
        total = total + p%npts
    end do
    write (*, '(a,i0,1x,i0)') 'status ', run%status, total
    call run_close(run)

contains

    subroutine check(st)
        integer(ip), intent(in) :: st
        if (st /= 0) then
            write (*, '(a)') 'frirom: '//trim(msg)
            error stop 1
        end if
    end subroutine check
end program cyclic_mode
