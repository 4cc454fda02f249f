!> frirom_aft from Fortran, as a legacy code would call it: the Jenkins closed form, the
!> Jacobian of the 1-D normal-load element against central differences, and every kind of
!> bad input returning a status code with a message instead of stopping.
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

    ! bad input: status codes and messages, never a stop
    p(1, 1) = -1.0_wp
    call aft_eval(plan, LAW_JENKINS, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_PARAM .or. index(msg, 'kt must be > 0') == 0) error stop 'kt < 0'
    p(1, 1) = kt
    call aft_eval(plan, 7_ip, x, p, w0, f, info, msg)
    if (info /= FRIROM_ERR_LAW) error stop 'unknown law'
    if (index(msg, 'law 7 (expected 1 jenkins, 2 normal1d, 3 normal2d, 4 cubic)') == 0) &
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
    real(wp) function ieee_nan()
        use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
        ieee_nan = ieee_value(1.0_wp, ieee_quiet_nan)
    end function ieee_nan
end program test_aft
