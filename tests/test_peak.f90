!> frirom_peak against a reference written independently: |x| sampled densely (cos(h t)
!> and sin(h t) from the intrinsics), every sampled local maximum refined by golden-section
!> search. Random series at H = 0..20 and scales 1e-150..1e150, and adversarial ones: pure
!> harmonics, a leading harmonic just below and just above the degree threshold, even
!> series (x'(pi) = 0: the companion polynomial loses its leading coefficient), the
!> maximum exactly at t = pi, a double root of x', constants and non-finite input.
!> Tolerance: 1e-12 sum|coefficients| (golden section resolves the peak's value to about
!> H^2 eps; the exact algorithm to round-off).
program test_peak
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_value, ieee_quiet_nan
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_NONFINITE, FRIROM_ERR_SIZE
    use frirom_peak, only: peak_amplitude, peak_amplitudes
    use frirom_check, only: check, check_done, fixed_seed
    implicit none
    real(wp), parameter :: pi = acos(-1.0_wp), rtol = 1.0e-12_wp
    real(wp), allocatable :: x(:), xs(:, :), amps(:), ts(:)
    real(wp) :: amp, t, worst, scale
    integer(ip) :: nh, k, info, ncase, nbad
    character(len=80) :: what

    call fixed_seed(28)
    worst = 0.0_wp
    ncase = 0
    nbad = 0

    ! random series, every H from 0 to 20, coefficients of many scales
    do nh = 0, 20
        do k = 1, 200
            allocate (x(2*nh + 1))
            call gaussian(x)
            if (mod(k, 3) == 0) call decay(x)
            scale = 10.0_wp**(-150 + 300*modulo(k*37, 101)/100)
            x = scale*x
            call compare(x, 'random series')
            deallocate (x)
        end do
    end do

    ! pure harmonics: max |x| = hypot(a_h, b_h) (+ |a0|)
    do nh = 1, 12
        do k = 1, nh
            allocate (x(2*nh + 1))
            x = 0.0_wp
            x(2*k) = 0.3_wp*k
            x(2*k + 1) = -0.7_wp
            x(1) = merge(0.25_wp, 0.0_wp, mod(k, 2) == 0)
            call peak_amplitude(x, amp, t, info)
            write (what, '(a, 2(1x, i0))') 'pure harmonic closed form H, h =', nh, k
            call check(info == FRIROM_OK .and. abs(amp - (abs(x(1)) + hypot(x(2*k), &
                       x(2*k + 1)))) <= 1.0e-14_wp*amp, trim(what))
            call compare(x, 'pure harmonic')
            deallocate (x)
        end do
    end do

    ! leading harmonic near the degree threshold (1e-12 of the largest), both sides
    do nh = 2, 10
        do k = 1, 20
            allocate (x(2*nh + 1))
            call gaussian(x)
            x(2*nh:2*nh + 1) = x(2*nh:2*nh + 1)*10.0_wp**(-10 - k*0.25_wp)
            call compare(x, 'degenerate leading harmonic')
            deallocate (x)
        end do
    end do

    ! even series (b = 0): x'(pi) = 0 for every coefficient set, a root at u = infinity
    do nh = 1, 15
        do k = 1, 20
            allocate (x(2*nh + 1))
            call gaussian(x)
            x(3::2) = 0.0_wp
            call compare(x, 'even series (root at t = pi)')
            ! the same shifted by a random phase: the root moves off pi
            call shift(x, 0.1_wp*k)
            call compare(x, 'even series shifted')
            deallocate (x)
        end do
    end do

    ! the maximum exactly at t = pi: x = cos t - 0.3 cos 2t, |x(pi)| = 1.3
    x = [0.0_wp, 1.0_wp, 0.0_wp, -0.3_wp, 0.0_wp]
    call peak_amplitude(x, amp, t, info)
    call check(info == FRIROM_OK .and. abs(amp - 1.3_wp) <= 1.0e-15_wp .and. &
               abs(t - pi) <= 1.0e-7_wp, 'maximum at t = pi')
    call compare(x, 'maximum at t = pi')

    ! a double root of x': x = sin t - sin(2t)/2, x'(t) = cos t - cos 2t, x'' (0) = 0
    x = [0.1_wp, 0.0_wp, 1.0_wp, 0.0_wp, -0.5_wp]
    call compare(x, 'double root of x''')
    ! an even series whose extrema include cos t = -1/(4 c)
    x = [0.2_wp, 1.0_wp, 0.0_wp, 0.8_wp, 0.0_wp]
    call compare(x, 'interior maximum of an even series')

    ! constants and H = 0
    call peak_amplitude([-3.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], amp, t, info)
    call check(info == FRIROM_OK .and. amp == 3.0_wp .and. t == 0.0_wp, 'constant series')
    call peak_amplitude([-2.5_wp], amp, t, info)
    call check(info == FRIROM_OK .and. amp == 2.5_wp, 'H = 0')
    call peak_amplitude([0.0_wp, 0.0_wp, 0.0_wp], amp, t, info)
    call check(info == FRIROM_OK .and. amp == 0.0_wp, 'zero series')

    ! bad input: non-finite, even length; the batch goes on past a bad column
    x = [1.0_wp, ieee_value(1.0_wp, ieee_quiet_nan), 0.0_wp]
    call peak_amplitude(x, amp, t, info)
    call check(info == FRIROM_ERR_NONFINITE .and. ieee_is_nan(amp), 'NaN coefficient')
    call peak_amplitude([1.0_wp, 2.0_wp], amp, t, info)
    call check(info == FRIROM_ERR_SIZE, 'even number of coefficients')

    ! the batch equals the single calls, with columns of every degree
    allocate (xs(9, 50), amps(50), ts(50))
    do k = 1, 50
        call gaussian(xs(:, k))
        xs(2*(1 + mod(k, 4)) + 2:, k) = 0.0_wp
    end do
    xs(3, 7) = ieee_value(1.0_wp, ieee_quiet_nan)
    block
        character(len=200) :: msg
        logical :: same
        integer(ip) :: st1
        msg = ''
        call peak_amplitudes(xs, amps, ts, info, msg)
        call check(info == FRIROM_ERR_NONFINITE .and. index(msg, 'column 7') > 0, &
                   'batch reports the NaN column: '//trim(msg))
        same = .true.
        do k = 1, 50
            call peak_amplitude(xs(:, k), amp, t, st1)
            if (k /= 7) same = same .and. amp == amps(k) .and. t == ts(k)
        end do
        call check(same .and. ieee_is_nan(amps(7)), 'batch equals single calls')
        call peak_amplitudes(xs, amps(1:3), ts, info, msg)
        call check(info == FRIROM_ERR_SIZE, 'batch size check')
    end block

    print '(a, es9.2, a, i0, a)', 'worst |amp - reference| / sum|x|: ', worst, ' (', nbad, &
        ' failures)'
    call check_done('test_peak')

contains

    !> Harmonic h divided by h^2: the fast decay of a smooth response.
    subroutine decay(v)
        real(wp), intent(inout) :: v(:)
        integer :: h
        do h = 1, (size(v) - 1)/2
            v(2*h:2*h + 1) = v(2*h:2*h + 1)/real(h*h, wp)
        end do
    end subroutine decay

    !> Standard normal draws (Box-Muller).
    subroutine gaussian(v)
        real(wp), intent(out) :: v(:)
        real(wp) :: u(2)
        integer :: j
        do j = 1, size(v)
            call random_number(u)
            v(j) = sqrt(-2.0_wp*log(1.0_wp - u(1)))*cos(2.0_wp*pi*u(2))
        end do
    end subroutine gaussian

    !> x(t) -> x(t - phi).
    subroutine shift(v, phi)
        real(wp), intent(inout) :: v(:)
        real(wp), intent(in) :: phi
        real(wp) :: a, b
        integer :: h
        do h = 1, (size(v) - 1)/2
            a = v(2*h)
            b = v(2*h + 1)
            v(2*h) = a*cos(h*phi) - b*sin(h*phi)
            v(2*h + 1) = a*sin(h*phi) + b*cos(h*phi)
        end do
    end subroutine shift

    !> |x(t)| from the intrinsics.
    real(wp) function absx(v, tt)
        real(wp), intent(in) :: v(:), tt
        integer :: h
        absx = v(1)
        do h = 1, (size(v) - 1)/2
            absx = absx + v(2*h)*cos(h*tt) + v(2*h + 1)*sin(h*tt)
        end do
        absx = abs(absx)
    end function absx

    !> Dense sampling plus golden-section refinement of every sampled local maximum.
    real(wp) function reference(v) result(best)
        real(wp), intent(in) :: v(:)
        real(wp), parameter :: g = (sqrt(5.0_wp) - 1.0_wp)/2.0_wp
        real(wp), allocatable :: s(:)
        real(wp) :: lo, hi, c, d, fc, fd
        integer :: ns, j, it
        ns = 64*size(v)
        allocate (s(0:ns - 1))
        do j = 0, ns - 1
            s(j) = absx(v, 2.0_wp*pi*j/ns)
        end do
        best = maxval(s)
        do j = 0, ns - 1
            if (s(j) < s(modulo(j - 1, ns)) .or. s(j) < s(modulo(j + 1, ns))) cycle
            lo = 2.0_wp*pi*(j - 1)/ns
            hi = 2.0_wp*pi*(j + 1)/ns
            c = hi - g*(hi - lo)
            d = lo + g*(hi - lo)
            fc = absx(v, c)
            fd = absx(v, d)
            do it = 1, 80
                if (fc > fd) then
                    hi = d
                    d = c
                    fd = fc
                    c = hi - g*(hi - lo)
                    fc = absx(v, c)
                else
                    lo = c
                    c = d
                    fc = fd
                    d = lo + g*(hi - lo)
                    fd = absx(v, d)
                end if
            end do
            best = max(best, fc, fd)
        end do
    end function reference

    !> frirom_peak against the reference: equal values, and |x(t)| at the returned time is
    !> the returned value.
    subroutine compare(v, label)
        real(wp), intent(in) :: v(:)
        character(len=*), intent(in) :: label
        real(wp) :: a, tt, r, tol, e
        integer(ip) :: st
        call peak_amplitude(v, a, tt, st)
        r = reference(v)
        tol = rtol*max(sum(abs(v)), tiny(1.0_wp))
        e = abs(a - r)/max(sum(abs(v)), tiny(1.0_wp))
        worst = max(worst, e)
        ncase = ncase + 1
        if (st /= FRIROM_OK .or. abs(a - r) > tol .or. abs(absx(v, tt) - a) > tol .or. &
            tt < 0.0_wp .or. tt >= 2.0_wp*pi) then
            nbad = nbad + 1
            write (what, '(a, i0, a, es10.3, a, es10.3)') 'H = ', (size(v) - 1)/2, ': ', a, &
                ' vs reference ', r
            call check(.false., label//', '//trim(what))
        end if
    end subroutine compare
end program test_peak
