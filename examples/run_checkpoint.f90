!> The joint case (cases/joint) from a legacy Fortran program through the run object
!> (module frirom_run; frirom_solve's frf_open opens it on a model given as triplets):
!> advanced a batch of points at a time, stopped after 30 points, checkpointed, closed,
!> and restored in a second run that finishes the curve; the restored curve equals the
!> uninterrupted one bit for bit. Then the banded formulation and one fixed-frequency solve.
!>
!> Build (an installed frirom): gfortran run_checkpoint.f90 $(pkg-config --cflags --libs
!> frirom). Prints "omega amp(tip:x) amp(platform:x) amp(platform:y)" per point of the
!> uninterrupted curve, then one line per check; stops with code 1 if a check fails.
program run_restart
    use frirom_kinds, only: wp, ip
    use frirom_run, only: run_t, run_points, run_start, run_advance, run_solve, run_close, &
                          run_checkpoint_size, run_checkpoint, run_restore, RUN_START_COLD, &
                          RUN_GOING, RUN_DONE, RUN_SOLVE_FIXED
    use frirom_solve, only: frf_settings, frf_open, peak_amplitude, FRF_BANDED
    implicit none
    integer(ip), parameter :: n = 5, nh = 5, nc = 2*nh + 1, batch = 10
    real(wp), parameter :: pi = acos(-1.0_wp)
    ! K (N/m): every entry; M (kg) diagonal. DoFs: platform:x, platform:y, blade_low:x,
    ! blade_mid:x, tip:x; one Jenkins element (kt N/m, mu, fn0 N) on u = cos 30 x + sin 30 y
    integer(ip), parameter :: kr(11) = [1, 2, 3, 1, 3, 4, 3, 4, 5, 4, 5], &
                              kc(11) = [1, 2, 1, 3, 3, 3, 4, 4, 4, 5, 5], md(5) = [1, 2, 3, 4, 5]
    real(wp), parameter :: kv(11) = [5.5e6_wp, 8e6_wp, -1.5e6_wp, -1.5e6_wp, 2.5e6_wp, &
                                     -1e6_wp, -1e6_wp, 1.6e6_wp, -6e5_wp, -6e5_wp, 6e5_wp], &
                           mv(5) = [0.08_wp, 0.08_wp, 0.03_wp, 0.03_wp, 0.02_wp]
    integer(ip), parameter :: ginfo(3, 1) = reshape([1, 1, 1], [3, 1]), gr(2) = [1, 1], &
                              gc(2) = [1, 2], outdofs(3) = [5, 1, 2]
    real(wp), parameter :: gv(2) = [0.8660254037844386_wp, 0.5_wp], &
                           params(3) = [1e7_wp, 0.5_wp, 100.0_wp]
    type(frf_settings) :: s
    type(run_t) :: run
    real(wp) :: fe(n, nc)
    real(wp), allocatable :: om_full(:), amp_full(:), om_cut(:), amp_cut(:), ck(:)
    integer(ip) :: info, at, k, nbad, nband
    character(len=512) :: msg
    logical :: same

    fe = 0.0_wp
    fe(5, 2) = 2.0_wp          ! 2 N cos(omega t) at the tip
    s%harmonics = nh
    s%samples = 64
    s%max_points = 1000
    msg = ''
    nbad = 0

    ! the uninterrupted curve
    call open_joint(s)
    call run_start(run, RUN_START_COLD, 2*pi*400.0_wp, 2*pi*520.0_wp, info, msg)
    call check(info)
    allocate (om_full(0), amp_full(0))
    call advance(0_ip, om_full, amp_full)
    call run_close(run)
    do k = 1, size(om_full)
        write (*, '(4es24.16)') om_full(k), amp_full(3*k - 2:3*k)
    end do
    write (*, '(a,l1,1x,i0)') 'complete ', .true., size(om_full)

    ! stopped after 30 points, checkpointed, restored in a new run
    call open_joint(s)
    call run_start(run, RUN_START_COLD, 2*pi*400.0_wp, 2*pi*520.0_wp, info, msg)
    call check(info)
    allocate (om_cut(0), amp_cut(0))
    call advance(30_ip, om_cut, amp_cut)
    at = size(om_cut)
    allocate (ck(run_checkpoint_size(run)))
    call run_checkpoint(run, ck, info, msg)
    call check(info)
    call run_close(run)
    call open_joint(s)
    call run_restore(run, ck, info, msg)
    call check(info)
    call advance(0_ip, om_cut, amp_cut)
    same = size(om_cut) == size(om_full)
    if (same) same = all(om_cut == om_full) .and. all(amp_cut == amp_full)
    write (*, '(a,i0,a,i0,a,a)') 'restored after ', at, ' points: ', size(om_cut), &
        ' points, ', merge('equal to the uninterrupted run', 'DIFFERENT                     ', &
                           same)
    if (.not. same) nbad = nbad + 1
    call run_close(run)

    ! the banded formulation completes the same range
    s%formulation = FRF_BANDED
    call open_joint(s)
    call run_start(run, RUN_START_COLD, 2*pi*400.0_wp, 2*pi*520.0_wp, info, msg)
    call check(info)
    deallocate (om_cut, amp_cut)
    allocate (om_cut(0), amp_cut(0))
    call advance(0_ip, om_cut, amp_cut)
    nband = size(om_cut)
    write (*, '(a,i0,a,l1)') 'banded: ', nband, ' points, complete ', run%status == RUN_DONE
    if (run%status /= RUN_DONE) nbad = nbad + 1
    call one_solve()
    call run_close(run)
    if (nbad > 0) error stop 1

contains

    subroutine open_joint(st)
        type(frf_settings), intent(in) :: st
        real(wp) :: zeta(5)
        zeta = 0.003_wp
        call frf_open(run, n, kr, kc, kv, md, md, mv, [integer(ip) ::], [integer(ip) ::], &
                      [real(wp) ::], 0.0_wp, 0.0_wp, zeta, ginfo, gr, gc, gv, params, fe, &
                      outdofs, st, info, msg)
        call check(info)
    end subroutine open_joint

    !> Advance until the run stops or has made `stop` points (0: no stop); append the
    !> frequencies and the outputs' peak amplitudes.
    subroutine advance(stop, om, amp)
        integer(ip), intent(in) :: stop
        real(wp), allocatable, intent(inout) :: om(:), amp(:)
        type(run_points) :: p
        integer(ip) :: j, o
        do while (run%status == RUN_GOING .and. (stop == 0 .or. size(om) < stop))
            call run_advance(run, batch, p, info, msg)
            call check(info)
            om = [om, p%lam]
            do j = 1, p%npts
                amp = [amp, [(peak_amplitude(p%xo(o, :, j)), o=1, 3)]]
            end do
        end do
    end subroutine advance

    !> One solve at 466 Hz from the linear solution on the open run.
    subroutine one_solve()
        type(run_points) :: p
        real(wp) :: y0(run%ny)
        y0 = 0.0_wp
        call run_solve(run, RUN_SOLVE_FIXED, 2*pi*466.0_wp, y0, p, info, msg, cold=.true.)
        call check(info)
        write (*, '(a,es14.6)') 'solve at 466 Hz: amp(tip:x) ', peak_amplitude(p%xo(1, :, 1))
    end subroutine one_solve

    subroutine check(st)
        integer(ip), intent(in) :: st
        if (st /= 0) then
            write (*, '(a)') 'frirom: '//trim(msg)
            error stop 2
        end if
    end subroutine check
end program run_restart
