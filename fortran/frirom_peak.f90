!> The peak over one period of a real trigonometric polynomial, exactly: the one algorithm
!> behind every reported amplitude (frirom.results.amplitude_max, the C API, frirom_solve).
!>
!> x(t) = a0 + sum_h a_h cos(h t) + b_h sin(h t), h = 1..H. Its extrema are roots of x'(t).
!> With u = tan(t / 2) and d the effective degree (the highest harmonic above round-off),
!> (1 + u^2)^d x'(t) is a real polynomial q(u) of degree 2d, whose real roots u give the
!> critical times t = 2 atan(u): the eigenvalues of q's companion matrix (LAPACK dgeev).
!> |x| is taken at those times, at the same times after one Newton step on x' (from
!> eigenvalue accuracy to round-off) and at 2(2H+1) equally spaced times (t = pi, where
!> u is infinite, among them), and the largest value is kept. Every candidate is a real
!> time, so the result never exceeds the true maximum, and it equals it to round-off
!> (complex roots only add harmless candidates).
module frirom_peak
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_NONFINITE, &
                             FRIROM_ERR_LAPACK, set_status
    use frirom_lapack, only: ilp, dgeev
    implicit none
    private
    public :: peak_amplitude, peak_amplitudes

    real(wp), parameter :: twopi = 2.0_wp*acos(-1.0_wp)
    !> A harmonic counts towards the degree when its magnitude exceeds this times the largest.
    real(wp), parameter :: deg_tol = 1.0e-12_wp
    !> A leading coefficient of q below this times its largest is a root at t = pi.
    real(wp), parameter :: lead_tol = 1.0e-13_wp
    !> Largest Newton step on x' (rad): a far step would leave the root's basin.
    real(wp), parameter :: max_step = 0.5_wp

contains

    !> max over one period of |x(t)| and a time where it is reached.
    !> A non-finite coefficient gives amp = t = NaN and info = FRIROM_ERR_NONFINITE; a
    !> failed eigen-solve (dgeev) FRIROM_ERR_LAPACK with the equally spaced samples' maximum.
    pure subroutine peak_amplitude(x, amp, t, info)
        real(wp), intent(in) :: x(:)          !! (2H+1) [a0, a1, b1, ..., aH, bH], any unit
        real(wp), intent(out) :: amp          !! max_t |x(t)|, the unit of x
        real(wp), intent(out) :: t            !! a time of the maximum, rad in [0, 2 pi)
        integer(ip), intent(out) :: info      !! FRIROM_OK, _NONFINITE, _LAPACK or _SIZE
        integer(ip) :: d
        real(wp), allocatable :: s(:, :)
        if (mod(size(x), 2) /= 1) then
            amp = ieee_value(amp, ieee_quiet_nan)
            t = amp
            info = FRIROM_ERR_SIZE
            return
        end if
        d = degree(x)
        allocate (s(0:2*d, d))
        call tan_half_basis(d, s)
        call peak_one(x, d, s, amp, t, info)
    end subroutine peak_amplitude

    !> peak_amplitude of every column of x; info is the first failure (its column in
    !> errmsg), the other columns are still computed.
    pure subroutine peak_amplitudes(x, amp, t, info, errmsg)
        real(wp), intent(in) :: x(:, :)       !! (2H+1, n) one coefficient vector per column
        real(wp), intent(out) :: amp(:)       !! (n) max_t |x(t)| per column
        real(wp), intent(out) :: t(:)         !! (n) a time of each maximum, rad in [0, 2 pi)
        integer(ip), intent(out) :: info      !! FRIROM_OK or the first column's failure
        character(len=*), intent(inout), optional :: errmsg  !! which column failed
        integer(ip) :: k, d, dmax, st
        real(wp), allocatable :: s(:, :), sd(:, :)
        character(len=24) :: where
        info = FRIROM_OK
        if (size(amp) /= size(x, 2) .or. size(t) /= size(x, 2) .or. mod(size(x, 1), 2) /= 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'peak_amplitudes: x must be '// &
                            '(2H+1, n) and amp, t (n)')
            return
        end if
        dmax = (size(x, 1) - 1)/2
        allocate (s(0:2*dmax, dmax))       ! the usual degree's basis, built once
        call tan_half_basis(dmax, s)
        do k = 1, size(x, 2)
            d = degree(x(:, k))
            if (d == dmax) then
                call peak_one(x(:, k), d, s, amp(k), t(k), st)
            else
                if (allocated(sd)) deallocate (sd)
                allocate (sd(0:2*d, d))
                call tan_half_basis(d, sd)
                call peak_one(x(:, k), d, sd, amp(k), t(k), st)
            end if
            if (st /= FRIROM_OK .and. info == FRIROM_OK) then
                write (where, '(i0)') k
                if (st == FRIROM_ERR_NONFINITE) then
                    call set_status(info, st, errmsg, 'peak_amplitudes: column '// &
                                    trim(where)//' has a NaN or Inf coefficient')
                else
                    call set_status(info, st, errmsg, 'peak_amplitudes: dgeev failed on '// &
                                    'the companion matrix of column '//trim(where))
                end if
            end if
        end do
    end subroutine peak_amplitudes

    !> Effective degree of x: its highest harmonic whose magnitude exceeds deg_tol times
    !> the largest (0 for a constant).
    pure function degree(x) result(d)
        real(wp), intent(in) :: x(:)          !! (2H+1) coefficients
        integer(ip) :: d
        real(wp) :: mag((size(x) - 1)/2)
        integer(ip) :: h
        do h = 1, size(mag)
            mag(h) = hypot(x(2*h), x(2*h + 1))
        end do
        d = 0
        if (size(mag) == 0) return
        do h = size(mag), 1, -1
            if (mag(h) > deg_tol*maxval(mag)) then
                d = h
                return
            end if
        end do
    end function degree

    !> s(m, h): (1 + i u)^(d+h) (1 - i u)^(d-h) = sum_m s(m, h) i^m u^m, integers exact in
    !> double precision up to d = 26 (|s| <= 2^(2d)). Then
    !> (1 + u^2)^d x'(t) = sum_h h Re[(b_h + i a_h) (1 + i u)^(d+h) (1 - i u)^(d-h)].
    pure subroutine tan_half_basis(d, s)
        integer(ip), intent(in) :: d          !! effective degree
        real(wp), intent(out) :: s(0:, :)     !! (0:2d, d)
        real(wp) :: cp(0:2*d), cm(0:2*d)
        integer(ip) :: h, m, j
        do h = 1, d
            call binomials(d + h, cp)
            call binomials(d - h, cm)
            do m = 0, 2*d
                s(m, h) = 0.0_wp
                do j = max(0, m - (d - h)), min(m, d + h)
                    s(m, h) = s(m, h) + cp(j)*cm(m - j)*merge(-1.0_wp, 1.0_wp, mod(m - j, 2) == 1)
                end do
            end do
        end do

    contains

        pure subroutine binomials(p, c)
            integer(ip), intent(in) :: p
            real(wp), intent(out) :: c(0:)
            integer(ip) :: k
            c = 0.0_wp
            c(0) = 1.0_wp
            do k = 1, p
                c(k) = c(k - 1)*real(p - k + 1, wp)/real(k, wp)
            end do
        end subroutine binomials
    end subroutine tan_half_basis

    !> The peak of x of effective degree d, with d's basis s.
    pure subroutine peak_one(x, d, s, amp, t, info)
        real(wp), intent(in) :: x(:)          !! (2H+1) coefficients
        integer(ip), intent(in) :: d          !! effective degree of x
        real(wp), intent(in) :: s(0:, :)      !! (0:2d, d) tan_half_basis(d)
        real(wp), intent(out) :: amp, t
        integer(ip), intent(out) :: info
        integer(ip) :: nh, ns, k, h, m, n
        integer(ilp) :: lwork, st
        real(wp) :: q(0:2*d), comp(2*d, 2*d), wr(2*d), wi(2*d), work(max(1, 6*2*d))
        real(wp) :: vl(1, 1), vr(1, 1)
        real(wp) :: lead, top, tk, v, d1, d2, step
        info = FRIROM_OK
        if (.not. all(ieee_is_finite(x))) then
            amp = ieee_value(amp, ieee_quiet_nan)
            t = amp
            info = FRIROM_ERR_NONFINITE
            return
        end if
        nh = (size(x) - 1)/2
        ns = 2*(2*nh + 1)
        amp = -1.0_wp
        t = 0.0_wp
        do k = 0, ns - 1
            call consider(twopi*real(k, wp)/real(ns, wp), amp, t)
        end do
        if (d == 0) return
        ! q(m): coefficient of u^m; i^m turns (b + i a) s into b s, -a s, -b s, a s
        do m = 0, 2*d
            q(m) = 0.0_wp
            do h = 1, d
                select case (mod(m, 4))
                case (0)
                    q(m) = q(m) + real(h, wp)*x(2*h + 1)*s(m, h)
                case (1)
                    q(m) = q(m) - real(h, wp)*x(2*h)*s(m, h)
                case (2)
                    q(m) = q(m) - real(h, wp)*x(2*h + 1)*s(m, h)
                case default
                    q(m) = q(m) + real(h, wp)*x(2*h)*s(m, h)
                end select
            end do
        end do
        ! a vanishing u^(2d) coefficient is a root at t = pi (u infinite), which the equally
        ! spaced candidates hold: deflate it (a tiny leading coefficient would make the
        ! companion matrix's norm, and the other roots' errors, huge)
        n = 2*d
        top = maxval(abs(q))
        do while (n > 0)
            if (abs(q(n)) > lead_tol*top) exit
            n = n - 1
        end do
        if (n == 0) return
        lead = q(n)
        comp = 0.0_wp
        do k = 1, n
            comp(1, k) = -q(n - k)/lead
        end do
        do k = 1, n - 1
            comp(k + 1, k) = 1.0_wp
        end do
        lwork = int(size(work), ilp)
        call dgeev('N', 'N', int(n, ilp), comp, int(2*d, ilp), wr, wi, vl, 1_ilp, vr, 1_ilp, &
                   work, lwork, st)
        if (st /= 0) then
            info = FRIROM_ERR_LAPACK
            return
        end if
        do k = 1, n
            call consider(2.0_wp*atan(wr(k)), amp, t)
        end do
        ! one Newton step on x' polishes each root (the roots as found stay candidates)
        do k = 1, n
            tk = 2.0_wp*atan(wr(k))
            call series(tk, v, d1, d2)
            step = 0.0_wp
            if (d2 /= 0.0_wp) step = max(-max_step, min(max_step, d1/d2))
            call consider(tk - step, amp, t)
        end do

    contains

        !> Keep time tt when |x(tt)| beats the best so far (the first of equal values).
        pure subroutine consider(tt, best, tbest)
            real(wp), intent(in) :: tt
            real(wp), intent(inout) :: best, tbest
            real(wp) :: x0, x1, x2
            call series(tt, x0, x1, x2)
            if (abs(x0) > best) then
                best = abs(x0)
                tbest = modulo(tt, twopi)
                if (tbest >= twopi) tbest = 0.0_wp
            end if
        end subroutine consider

        !> x, x' and x'' at tt (cos h t, sin h t by the rotation recurrence: error ~h eps).
        pure subroutine series(tt, x0, x1, x2)
            real(wp), intent(in) :: tt
            real(wp), intent(out) :: x0, x1, x2
            real(wp) :: c1, s1, c, sn, cn, ev, od
            integer(ip) :: hh
            c1 = cos(tt)
            s1 = sin(tt)
            c = 1.0_wp
            sn = 0.0_wp
            x0 = x(1)
            x1 = 0.0_wp
            x2 = 0.0_wp
            do hh = 1, nh
                cn = c*c1 - sn*s1
                sn = sn*c1 + c*s1
                c = cn
                ev = x(2*hh)*c + x(2*hh + 1)*sn
                od = x(2*hh + 1)*c - x(2*hh)*sn
                x0 = x0 + ev
                x1 = x1 + hh*od
                x2 = x2 - hh*hh*ev
            end do
        end subroutine series
    end subroutine peak_one
end module frirom_peak
