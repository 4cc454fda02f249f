!> frirom_aft from Fortran, as a legacy code would call it: the Jenkins closed form, the
!> Jacobian of the 1-D normal-load element against central differences, the 2-D element's
!> closed cycle against its plain march run to convergence, and every kind of bad input
!> returning a status code with a message instead of stopping.
program test_aft
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_aft
    implicit none
    integer(ip), parameter :: nh = 3, nc = 2*nh + 1, ns = 256
    type(aft_plan) :: plan
    integer(ip) :: info, per(1), j, c, d
    real(wp) :: x(nc, 1, 1), p(3, 1), w0(1, 1), f(nc, 1, 1)
    real(wp) :: x2(nc, 2, 1), p2(4, 1), f2(nc, 2, 1), fp(nc, 2, 1), fm(nc, 2, 1)
    real(wp) :: jac(2*nc, 2*nc, 1), fd(2*nc, 2*nc), ts, a1, b1, kt, fs, amp, h, err
    character(len=300) :: msg

    call aft_plan_create(plan, nh, ns, info, msg)
    if (info /= FRIROM_OK) error stop 'plan'
    ! Jenkins under u = A cos: closed-form first harmonic, error <= 10/N^2 (see pytest)
    kt = 1.0e5_wp
    fs = 30.0_wp
    amp = 1.0e-3_wp
    x = 0.0_wp
    x(2, 1, 1) = amp
    p(:, 1) = [kt, 0.3_wp, 100.0_wp]
    w0 = 0.0_wp
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg, periods=per)
    if (info /= FRIROM_OK) error stop 'jenkins eval'
    ts = acos(1.0_wp - 2.0_wp*fs/(kt*amp))
    a1 = 2/acos(-1.0_wp)*((2*fs - kt*amp)*sin(ts) + kt*amp*(ts/2 + sin(2*ts)/4))
    b1 = 2/acos(-1.0_wp)*((fs - kt*amp)*(1 - cos(ts)) + kt*amp*sin(ts)**2/2 - fs*(1 + cos(ts)))
    if (abs(f(2, 1, 1) - a1) + abs(f(3, 1, 1) - b1) > 10.0_wp/ns**2*hypot(a1, b1)) &
        error stop 'Jenkins first harmonic off the closed form'
    if (per(1) /= 2) error stop 'Jenkins from a cold slider closes in the second period'

    ! normal-load element with lift-off: analytical vs central-difference Jacobian
    x2 = 0.0_wp
    x2(2, 1, 1) = 1.0e-3_wp
    x2(5, 1, 1) = 0.2e-3_wp
    x2(3, 2, 1) = 1.2e-3_wp
    x2(4, 2, 1) = 0.3e-3_wp
    p2(:, 1) = [kt, 0.8_wp*kt, 0.4_wp, 60.0_wp]
    call aft_eval(plan, LAW_NORMAL1D, x2, p2, w0, f2, info, msg, jac=jac)
    if (info /= FRIROM_OK) error stop 'normal1d eval'
    h = 1.0e-9_wp
    do j = 1, 2*nc
        c = mod(j - 1, nc) + 1
        d = (j - 1)/nc + 1
        x2(c, d, 1) = x2(c, d, 1) + h
        call aft_eval(plan, LAW_NORMAL1D, x2, p2, w0, fp, info, msg)
        x2(c, d, 1) = x2(c, d, 1) - 2*h
        call aft_eval(plan, LAW_NORMAL1D, x2, p2, w0, fm, info, msg)
        x2(c, d, 1) = x2(c, d, 1) + h
        fd(:, j) = reshape(fp - fm, [2*nc])/(2*h)
    end do
    err = maxval(abs(jac(:, :, 1) - fd))/maxval(abs(fd))
    if (err > 1.0e-5_wp) error stop 'normal1d Jacobian differs from central differences'

    call check_normal2d_against_plain_march()
    call check_normal2d_carried_slider()

    ! bad input: status codes and messages, never a stop
    p(1, 1) = -1.0_wp
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_PARAM .or. index(msg, 'kt must be > 0') == 0) error stop 'kt < 0'
    p(1, 1) = kt
    call aft_eval(plan, 9_ip, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_LAW) error stop 'unknown law'
    if (index(msg, 'law 9 (expected 1 jenkins, 2 normal1d, 3 normal2d, 4 cubic, 5 iwan4, '// &
                  '6 iwan)') == 0) &
        error stop 'unknown law: the message lists the laws of the table'
    call aft_eval(plan, LAW_NORMAL1D, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_SIZE) error stop 'wrong number of directions'
    x(1, 1, 1) = ieee_nan()
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_NONFINITE) error stop 'NaN input'
    call aft_plan_destroy(plan)
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_PARAM) error stop 'destroyed plan must be refused'
    print '(a)', 'test_aft: ok'
contains
    !> The 2-D cycles the AFT closes (plain periods accelerated by Newton steps on the
    !> slider, frirom_aft_march) against the law marched here plainly from the same cold
    !> slider for 20 000 periods with no closure logic (the mismatch then is below 1e-15
    !> of the amplitude even at 0.991 per period): forces at every sample within 1e-10 of
    !> their scale (the AFT stops at a mismatch of 1e-12, whose effect on the forces the
    !> slow contraction amplifies up to 1/(1 - 0.991) ~ 1e2). Cases: the onset of partial
    !> slip (plain marching needs more than the default 200 periods to close), slower and
    !> faster slip, normal load variation, lift-off, a contact that slips while the march
    !> settles and then sticks for good (its slider depends on the path: equal to round-off,
    !> since no step may end a march stuck), and one that settles slowly onto a closed cycle
    !> that only touches the friction limit. Prints the plain and AFT period counts.
    subroutine check_normal2d_against_plain_march()
        integer(ip), parameter :: ncase = 7, nplain = 20000
        ! u1 = a cos + m1, u2 = b cos(tau - 0.3) + m2, v = c cos; kt, kn, mu, n0
        real(wp), parameter :: cases(9, ncase) = reshape([ &
            0.301e-3_wp, 0.02e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0e5_wp, 0.0_wp, 0.3_wp, 100.0_wp, &
            0.305e-3_wp, 0.1e-3_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0e5_wp, 0.0_wp, 0.3_wp, 100.0_wp, &
            0.33e-3_wp, 0.02e-3_wp, 0.0_wp, 0.0_wp, 0.1e-3_wp, 1.0e5_wp, 1.0e5_wp, 0.3_wp, &
            100.0_wp, &
            0.6e-3_wp, 0.1e-3_wp, 0.0_wp, 0.0_wp, 0.1e-3_wp, 1.0e5_wp, 1.0e5_wp, 0.3_wp, &
            100.0_wp, &
            0.5e-3_wp, 0.2e-3_wp, 0.0_wp, 0.0_wp, 1.5e-3_wp, 1.0e5_wp, 1.0e5_wp, 0.3_wp, &
            100.0_wp, &
            0.05e-3_wp, 0.03e-3_wp, 0.6e-3_wp, 0.36e-3_wp, 0.02e-3_wp, 1.0e5_wp, 1.0e5_wp, &
            0.3_wp, 80.0_wp, &
            0.299e-3_wp, 0.01e-3_wp, 0.0_wp, 0.5e-3_wp, 0.0_wp, 1.0e5_wp, 0.0_wp, 0.3_wp, &
            100.0_wp], [9, ncase])
        real(wp) :: xc(nc, 3, 1), pc(4, 1), wz(2, 1), xt(ns, 3, 1), ft(ns, 3, 1)
        real(wp) :: fc(nc, 3, 1), w(1, 2), fr(1, ns, 3), last, ferr, fscale
        integer(ip) :: i, per_aft(1), per_plain, st(1, ns)
        wz = 0.0_wp
        do i = 1, ncase
            xc = 0.0_wp
            xc(2, 1, 1) = cases(1, i)
            xc(2, 2, 1) = cases(2, i)*cos(0.3_wp)
            xc(3, 2, 1) = cases(2, i)*sin(0.3_wp)
            xc(1, 1, 1) = cases(3, i)
            xc(1, 2, 1) = cases(4, i)
            xc(2, 3, 1) = cases(5, i)
            pc(:, 1) = cases(6:9, i)
            call aft_eval(plan, LAW_NORMAL2D, xc, pc, wz, fc, info, msg, periods=per_aft)
            if (info /= FRIROM_OK) error stop 'normal2d: the AFT did not close'
            call aft_time(plan, LAW_NORMAL2D, xc, pc, wz, xt, ft, info, msg)
            if (info /= FRIROM_OK) error stop 'normal2d: aft_time'
            w = 0.0_wp
            call march_plainly(xt, pc, w, nplain, fr, st, per_plain, last)
            if (last > 1.0e-15_wp) &
                error stop 'normal2d: the plain reference march has not converged'
            fscale = maxval(abs(fr))
            ferr = force_error(ft, fr)
            print '(a,i0,a,i0,a,i0,a,es9.2,a,f5.3)', 'normal2d case ', i, ': plain march ', &
                per_plain, ' periods, AFT ', per_aft(1), '; force error ', ferr/fscale, &
                ', slip fraction ', real(count(st == 2), wp)/ns
            if (ferr > 1.0e-10_wp*fscale) error stop 'normal2d: closed cycle off the plain march'
            ! never slower than plain marching; the onset of partial slip (case 1) and the
            ! slow settling (case 7) close within the default 200 periods, plain needs more
            if (per_aft(1) > per_plain) error stop 'normal2d: steps slowed the march'
            if (i == 1 .and. (per_plain <= 200 .or. per_aft(1) > 10)) &
                error stop 'normal2d: onset of partial slip'
            if (i == ncase .and. (per_plain <= 200 .or. per_aft(1) > 100)) &
                error stop 'normal2d: slow settling onto a touching cycle'
        end do
    end subroutine check_normal2d_against_plain_march

    real(wp) function ieee_nan()
        use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
        ieee_nan = ieee_value(1.0_wp, ieee_quiet_nan)
    end function ieee_nan

    !> Two 2-D cycles from the paper_hooks case (coarse, ROM_I, normal2d, lug tied, f0 =
    !> 1 000 N, near 180.2 Hz: H = 1, N = 128), each marched from the slider the previous
    !> continuation point left: 1-2 samples of 128 slip, and plain marching contracts the
    !> mismatch by only 1 - 3e-5 a period (4 345 and 6 822 periods to close). Their sliders
    !> are weakly determined (det(I - M) < DET_ISOLATED), so they are history: the cycle is
    !> the plain march from w0, closed on its drift (DRIFT a period) or after max_periods
    !> periods, not the far fixed point (~1/det away, and as sensitive to the motion; the
    !> plain march of 200 000 periods is printed for scale). Checked: (1) the forces are
    !> those of a plain march of the periods the AFT reports, to 1e-12; (2) the count is
    !> returned in held, and with it held the Jacobian equals central differences (the
    !> Newton corrector holds the counts: frirom_aft HELD); it stalled at 181.3 Hz when
    !> the stepped fixed point was kept with a Jacobian that held its slider.
    subroutine check_normal2d_carried_slider()
        integer(ip), parameter :: h1 = 1, c1 = 3, s1 = 128, nplain = 200000
        real(wp), parameter :: cases(15, 2) = reshape([ &
            -1.44588663306526642e-08_wp, 1.23934174140885480e-07_wp, 4.85649176741841169e-08_wp, &
            3.80100908726234899e-08_wp, -7.14112730830618121e-08_wp, &
            -2.52202748185404346e-08_wp, 5.12160333005927734e-09_wp, &
            -3.46117733177589280e-09_wp, -2.51913870865386229e-09_wp, 5.55556e7_wp, &
            1.11111e8_wp, 0.3_wp, 2.77777777777777786e+01_wp, -1.42176960264330240e-08_wp, &
            3.35594065619377310e-08_wp, &
            -1.47689580338017130e-08_wp, 1.23906642650487870e-07_wp, 4.85405484926914831e-08_wp, &
            3.74768265493342011e-08_wp, -7.13927292349163880e-08_wp, &
            -2.52047894485039442e-08_wp, 5.09983102394981281e-09_wp, &
            -3.46062142293166551e-09_wp, -2.51758210551822211e-09_wp, 5.55556e7_wp, &
            1.11111e8_wp, 0.3_wp, 2.77777777777777786e+01_wp, -1.29361805674124377e-08_wp, &
            3.57078416284049260e-08_wp], [15, 2])
        type(aft_plan) :: pl
        real(wp) :: xc(c1, 3, 1), pc(4, 1), wc(2, 1), fc(c1, 3, 1), xt(s1, 3, 1), ft(s1, 3, 1)
        real(wp) :: w(1, 2), fr(1, s1, 3), last, ferr, fscale, jc(3*c1, 3*c1, 1), jfd(3*c1)
        real(wp) :: xp(c1, 3, 1), fpl(c1, 3, 1), fmi(c1, 3, 1), step, jerr
        integer(ip) :: i, k, per(1), st(1, s1), held(1), q
        call aft_plan_create(pl, h1, s1, info, msg)
        if (info /= FRIROM_OK) error stop 'normal2d carried: plan'
        do i = 1, 2
            xc(:, :, 1) = reshape(cases(1:9, i), [c1, 3])
            pc(:, 1) = cases(10:13, i)
            wc(:, 1) = cases(14:15, i)
            held = 0
            call aft_eval(pl, LAW_NORMAL2D, xc, pc, wc, fc, info, msg, jac=jc, periods=per, &
                          held=held)
            if (info /= FRIROM_OK) error stop 'normal2d carried: the AFT did not close'
            if (held(1) /= per(1)) error stop 'normal2d carried: not held as history'
            call aft_time(pl, LAW_NORMAL2D, xc, pc, wc, xt, ft, info, msg)
            if (info /= FRIROM_OK) error stop 'normal2d carried: aft_time'
            w(1, :) = wc(:, 1)
            call march_plainly(xt, pc, w, per(1), fr, st, k, last)
            fscale = maxval(abs(fr))
            ferr = force_error(ft, fr)
            w(1, :) = wc(:, 1)
            call march_plainly(xt, pc, w, nplain, fr, st, k, last)
            ! with held: the same function of x at every point of the differences
            jerr = 0.0_wp
            step = 1.0e-8_wp*maxval(abs(xc))
            do q = 1, 3*c1
                xp = xc
                xp(mod(q - 1, c1) + 1, (q - 1)/c1 + 1, 1) = xc(mod(q - 1, c1) + 1, &
                                                                (q - 1)/c1 + 1, 1) + step
                call aft_eval(pl, LAW_NORMAL2D, xp, pc, wc, fpl, info, msg, held=held)
                xp(mod(q - 1, c1) + 1, (q - 1)/c1 + 1, 1) = xc(mod(q - 1, c1) + 1, &
                                                                (q - 1)/c1 + 1, 1) - step
                call aft_eval(pl, LAW_NORMAL2D, xp, pc, wc, fmi, info, msg, held=held)
                jfd = reshape(fpl - fmi, [3*c1])/(2.0_wp*step)
                jerr = max(jerr, maxval(abs(jfd - jc(:, q, 1))))
            end do
            jerr = jerr/maxval(abs(jc))
            print '(a,i0,a,i0,a,es9.2,a,es9.2,a,es9.2)', 'normal2d carried slider case ', i, &
                ': AFT ', per(1), ' periods (history); against the plain march ', ferr/fscale, &
                '; Jacobian against differences ', jerr, '; the far fixed point differs by ', &
                force_error(ft, fr)/fscale
            if (ferr > 1.0e-12_wp*fscale) error stop 'normal2d carried: not the plain march'
            if (jerr > 1.0e-6_wp) error stop 'normal2d carried: Jacobian'
        end do
        call aft_plan_destroy(pl)
    end subroutine check_normal2d_carried_slider
    !> The 2-D law marched plainly, nper periods from slider w (in/out), over the time
    !> histories xt (ns, 3, 1) of aft_time: the last period's forces fr and states st, the
    !> first period whose slider mismatch is below 1e-12 of the displacement scale (0:
    !> none) and the last period's mismatch over that scale.
    subroutine march_plainly(xt, pc, w, nper, fr, st, first, last)
        use frirom_contact, only: friction2d_march, recontact_follow
        real(wp), intent(in) :: xt(:, :, :), pc(:, :)
        real(wp), intent(inout) :: w(:, :)
        integer(ip), intent(in) :: nper
        real(wp), intent(out) :: fr(:, :, :), last
        integer(ip), intent(out) :: st(:, :), first
        real(wp) :: uf(1, size(xt, 1), 2), tg(1, 12, size(xt, 1)), wst(2), scale
        integer(ip) :: k
        do k = 1, 2
            call recontact_follow(transpose(xt(:, k, :)), transpose(xt(:, 3, :)), &
                                  pc(2, :), pc(4, :), uf(:, :, k))
        end do
        scale = maxval(abs(xt(:, 1:3, 1)))
        first = 0
        do k = 1, nper
            wst = w(1, :)
            call friction2d_march(uf(:, :, 1), uf(:, :, 2), transpose(xt(:, 3, :)), &
                                  pc(1, :), pc(2, :), pc(3, :), pc(4, :), w, &
                                  fr(:, :, 1), fr(:, :, 2), fr(:, :, 3), st, tg)
            if (first == 0 .and. maxval(abs(w(1, :) - wst)) <= 1.0e-12_wp*scale) first = k
        end do
        last = maxval(abs(w(1, :) - wst))/scale
    end subroutine march_plainly

    !> Largest difference between the AFT's closed-cycle forces ft (ns, 3, 1) and the plain
    !> march's fr (1, ns, 3), N.
    real(wp) function force_error(ft, fr)
        real(wp), intent(in) :: ft(:, :, :), fr(:, :, :)
        integer(ip) :: k
        force_error = 0.0_wp
        do k = 1, 3
            force_error = max(force_error, maxval(abs(ft(:, k, 1) - fr(1, :, k))))
        end do
    end function force_error
end program test_aft
