!> Contact laws in the time domain: pure procedures, no state beyond what the caller passes.
!>
!> Each march takes the relative displacements of m elements at the N samples of one
!> period, laid out (m, N), and their slider positions at the start, and returns the
!> forces, the contact state and the local derivatives at every sample, leaving the
!> sliders at their end-of-period positions. Elements advance together, sample after
!> sample, with branch-free updates: the slider recurrence of one element is a serial
!> chain, but m independent chains side by side vectorise and hide its latency.
!> The AFT (frirom_aft) repeats the march until the cycles close and turns the local
!> derivatives into the harmonic Jacobian.
!>
!> Sign convention: forces are those the element exerts against the relative displacement
!> (f_t = kt (u - w) in stick), so a stuck element is a spring of stiffness kt.
!>
!> Slider rules (Yang, Chu and Menq 1998 for the 1-D element with normal load variation;
!> the predictor-corrector used by Petrov and Ewins for the 2-D element):
!> - normal force f_n = max(n0 + kn v, 0); n0 < 0 is an initial gap g0 = -n0/kn;
!> - lift-off (f_n = 0): no tangential force, and the slider follows the contact point
!>   (w = u), so that the contact recloses unstretched where it touches down, at the
!>   re-contact instant between two samples: the marches take, in place of u, the
!>   positions recontact_follow gives (u, except at the last open sample before the
!>   contact recloses, where it is u at the instant the linearly interpolated normal force
!>   crosses zero). Anchoring the slider at that open sample instead would be off by
!>   O(1/N) for the whole stick that follows: a first-order AFT. Done before the march,
!>   once for all its periods, the march itself stays as lean as without lift-off;
!> - otherwise the trial force kt (u - w) sticks when it lies within the friction limit
!>   mu f_n; beyond it the element slips, the force sits on the limit in the trial's
!>   direction and the slider moves to w = u - f_t/kt. A normal load that drops during
!>   stick therefore starts slip at the right sample: the test uses the current f_n.
module frirom_contact
    use frirom_kinds, only: wp, ip
    implicit none
    private

    public :: STATE_LIFTOFF, STATE_STICK, STATE_SLIP
    public :: jenkins_march, friction1d_march, friction2d_march, cubic_spring
    public :: recontact_follow, slip2d_step

    integer(ip), parameter :: STATE_LIFTOFF = 0  !! open contact, no force
    integer(ip), parameter :: STATE_STICK = 1    !! tangential spring, slider fixed
    integer(ip), parameter :: STATE_SLIP = 2     !! force on the friction limit, slider moves

contains

    !> Jenkins elements (elastic Coulomb, constant normal load fn0) over one period.
    pure subroutine jenkins_march(u, kt, mu, fn0, w, ft, state)
        real(wp), intent(in) :: u(:, :)          !! (m, N) tangential relative displacement, m
        real(wp), intent(in) :: kt(:), mu(:), fn0(:)  !! (m) N/m, -, N
        real(wp), intent(inout) :: w(:)          !! (m) slider position: start in, end out, m
        real(wp), intent(out) :: ft(:, :)        !! (m, N) tangential force, N
        integer(ip), intent(out) :: state(:, :)  !! (m, N) STATE_*
        integer(ip) :: j, k
        real(wp) :: t, lim, f, fs, ws
        logical :: slip
        ! An open contact (fn0 = 0) has lim = 0: the slip update then gives f = 0 and
        ! w = u, the lift-off rules, so one branch-free update serves all states.
        do k = 1, size(u, 2)
            do j = 1, size(u, 1)
                lim = mu(j)*merge(fn0(j), 0.0_wp, fn0(j) > 0.0_wp)
                t = kt(j)*(u(j, k) - w(j))
                slip = abs(t) > lim
                fs = sign(lim, t)
                ws = u(j, k) - fs/kt(j)
                f = merge(fs, t, slip)
                w(j) = merge(ws, w(j), slip)
                ft(j, k) = f
                state(j, k) = merge(STATE_SLIP, STATE_STICK, slip)
                state(j, k) = merge(STATE_LIFTOFF, state(j, k), fn0(j) <= 0.0_wp)
            end do
        end do
    end subroutine jenkins_march

    !> 1-D elements with normal load variation over one period.
    !> dft_dv(j, k) = d f_t / d v at the same sample: s mu kn at slip samples, 0 elsewhere
    !> (the only same-sample derivative besides kt in stick and kn in contact).
    pure subroutine friction1d_march(u, v, kt, kn, mu, n0, w, ft, fn, state, dft_dv)
        real(wp), intent(in), contiguous :: u(:, :)   !! (m, N) tangential relative displ.
                                                      !! (recontact_follow's uf), m
        real(wp), intent(in), contiguous :: v(:, :)   !! (m, N) normal relative displacement,
                                                      !! m (positive closes)
        real(wp), intent(in), contiguous :: kt(:), kn(:), mu(:), n0(:)  !! (m) N/m, N/m, -, N
        real(wp), intent(inout), contiguous :: w(:)   !! (m) slider: start in, end out, m
        real(wp), intent(out), contiguous :: ft(:, :), fn(:, :)  !! (m, N) forces, N
        integer(ip), intent(out), contiguous :: state(:, :)     !! (m, N) STATE_*
        real(wp), intent(out), contiguous :: dft_dv(:, :)       !! (m, N) see above, N/m
        integer(ip) :: j, k
        real(wp) :: t, lim, f, nf, closed, fs, ws, ds
        logical :: slip
        ! Contiguous arguments: the loop over elements vectorises at full width (AVX-512: 8
        ! elements a vector) instead of the 2 lanes a possibly strided section allows.
        ! Open contact: lim = 0, so the slip update gives f = 0 and w = u (lift-off rules)
        ! and one branch-free update serves all states; `closed` zeroes d ft/dv there.
        do k = 1, size(u, 2)
            do j = 1, size(u, 1)
                nf = n0(j) + kn(j)*v(j, k)
                closed = merge(1.0_wp, 0.0_wp, nf > 0.0_wp)
                nf = closed*nf   ! max(nf, 0) without the branch gfortran's MAX carries
                lim = mu(j)*nf
                t = kt(j)*(u(j, k) - w(j))
                slip = abs(t) > lim
                ! operands computed unconditionally so the selects are blends, not branches
                fs = sign(lim, t)
                ws = u(j, k) - fs/kt(j)
                ds = sign(mu(j)*kn(j), t)
                f = merge(fs, t, slip)
                w(j) = merge(ws, w(j), slip)
                ft(j, k) = f
                fn(j, k) = nf
                dft_dv(j, k) = closed*merge(ds, 0.0_wp, slip)
                state(j, k) = merge(STATE_SLIP, STATE_STICK, slip)
                state(j, k) = merge(STATE_LIFTOFF, state(j, k), closed == 0.0_wp)
            end do
        end do
    end subroutine friction1d_march

    !> 2-D tangential elements (circular friction limit) with normal load variation over one
    !> period. Between two closed samples the motion is taken linear in u and in the friction
    !> limit (the normal load), and the slider is advanced exactly along that path
    !> (slip2d_step): stick until the trial force reaches the limit (located between the
    !> samples), then the slip direction turns towards the motion as the closed form of the
    !> pursuit equation says. With the samples exact to O(h^2) this makes the slider second
    !> order, where a radial return at each sample (backward Euler) is first order on curved
    !> slip paths. After an open sample the slider sits at the re-contact point (uf) and the
    !> limit grows from zero there: the slip direction is then that of the motion and the
    !> radial return is exact. At slip samples the local tangent of f_t is returned:
    !> d f_t(k) = G_k (du_{k-1} - dw_{k-1}) + A_k (du_k - du_{k-1}) + b_k dv_k + c_k dv_{k-1},
    !> tangent(j, 1:4, k) = G_k, (j, 5:6, k) = b_k, (j, 7:10, k) = A_k (2x2 column-major),
    !> (j, 11:12, k) = c_k (zero at other samples). After an open sample A_k = G_k =
    !> (mu f_n / |t|) kt (I - n n^T), b_k = mu kn n, c_k = 0 (t: the trial force, n = t/|t|).
    !> A start slider beyond the limit (the first period from a given w) first slides
    !> radially onto it at the previous sample; that sample is then a slip sample.
    pure subroutine friction2d_march(u1, u2, v, kt, kn, mu, n0, w, f1, f2, fn, state, tangent)
        real(wp), intent(in) :: u1(:, :), u2(:, :)  !! (m, N) in-plane tangential displ.
                                                    !! (recontact_follow's uf), m
        real(wp), intent(in) :: v(:, :)          !! (m, N) normal relative displacement, m
        real(wp), intent(in) :: kt(:), kn(:), mu(:), n0(:)  !! (m) N/m, N/m, -, N
        real(wp), intent(inout) :: w(:, :)       !! (m, 2) slider position: start in, end out
        real(wp), intent(out) :: f1(:, :), f2(:, :), fn(:, :)  !! (m, N) forces, N
        integer(ip), intent(out) :: state(:, :)  !! (m, N) STATE_*
        real(wp), intent(out) :: tangent(:, :, :)  !! (m, 12, N) slip tangents, see above
        integer(ip) :: j, k, kp, n
        real(wp) :: t1, t2, tn, lim, limp, n1, n2, r, nf, nfp, g1, g2
        real(wp) :: z0(2), du(2), nv(2), dn(2, 6), r0, r1, rz, g(2), tgl(12)
        logical :: slip, open
        !> |z0|^2 beyond r0^2 by this fraction: a start slider outside the limit
        real(wp), parameter :: OUTSIDE = 1.0e-10_wp
        n = size(u1, 2)
        do k = 1, n
            kp = k - 1
            if (k == 1) kp = n
            do j = 1, size(u1, 1)
                nf = n0(j) + kn(j)*v(j, k)
                nfp = n0(j) + kn(j)*v(j, kp)
                open = nf <= 0.0_wp
                nf = max(nf, 0.0_wp)
                lim = mu(j)*nf
                limp = mu(j)*max(nfp, 0.0_wp)
                fn(j, k) = nf
                tangent(j, :, k) = 0.0_wp
                if (open) then
                    w(j, 1) = u1(j, k)
                    w(j, 2) = u2(j, k)
                    f1(j, k) = 0.0_wp
                    f2(j, k) = 0.0_wp
                    state(j, k) = STATE_LIFTOFF
                    cycle
                end if
                t1 = kt(j)*(u1(j, k) - w(j, 1))
                t2 = kt(j)*(u2(j, k) - w(j, 2))
                if (limp <= 0.0_wp .or. lim <= 0.0_wp) then
                    ! after an open sample (or without friction): radial return, exact here
                    tn = hypot(t1, t2)
                    slip = tn > lim
                    n1 = t1/max(tn, tiny(1.0_wp))
                    n2 = t2/max(tn, tiny(1.0_wp))
                    g1 = merge(lim*n1, t1, slip)
                    g2 = merge(lim*n2, t2, slip)
                    w(j, 1) = merge(u1(j, k) - g1/kt(j), w(j, 1), slip)
                    w(j, 2) = merge(u2(j, k) - g2/kt(j), w(j, 2), slip)
                    f1(j, k) = g1
                    f2(j, k) = g2
                    state(j, k) = merge(STATE_SLIP, STATE_STICK, slip)
                    if (.not. slip) cycle
                    r = lim/max(tn, tiny(1.0_wp))*kt(j)
                    tangent(j, 1, k) = r*(1.0_wp - n1*n1)
                    tangent(j, 2, k) = -r*n1*n2
                    tangent(j, 3, k) = -r*n1*n2
                    tangent(j, 4, k) = r*(1.0_wp - n2*n2)
                    tangent(j, 5, k) = mu(j)*kn(j)*n1
                    tangent(j, 6, k) = mu(j)*kn(j)*n2
                    tangent(j, 7:10, k) = tangent(j, 1:4, k)
                    cycle
                end if
                z0 = [u1(j, kp) - w(j, 1), u2(j, kp) - w(j, 2)]
                du = [u1(j, k) - u1(j, kp), u2(j, k) - u2(j, kp)]
                r0 = limp/kt(j)
                r1 = lim/kt(j)
                rz = norm2(z0)
                if (rz**2 > r0**2*(1.0_wp + OUTSIDE)) then
                    ! a start slider beyond the limit (the first period from a given w):
                    ! it slides radially onto the limit at sample kp, z0 -> r0 z0/|z0|
                    call outside_step(z0/rz, rz, du, r0, r1, kt(j), mu(j)*kn(j), g, tgl)
                    tangent(j, :, k) = tgl
                    w(j, 1) = u1(j, k) - g(1)/kt(j)
                    w(j, 2) = u2(j, k) - g(2)/kt(j)
                    f1(j, k) = g(1)
                    f2(j, k) = g(2)
                    state(j, k) = STATE_SLIP
                    cycle
                end if
                call slip2d_step(z0, du, r0, r1, slip, nv, dn)
                if (.not. slip) then
                    f1(j, k) = t1
                    f2(j, k) = t2
                    state(j, k) = STATE_STICK
                    cycle
                end if
                w(j, 1) = u1(j, k) - r1*nv(1)
                w(j, 2) = u2(j, k) - r1*nv(2)
                f1(j, k) = lim*nv(1)
                f2(j, k) = lim*nv(2)
                state(j, k) = STATE_SLIP
                ! f = kt r1 n1(z0, du, r0, r1), r = mu (n0 + kn v)/kt
                tangent(j, 1, k) = lim*dn(1, 1)      ! (a reshape here was a library call)
                tangent(j, 2, k) = lim*dn(2, 1)
                tangent(j, 3, k) = lim*dn(1, 2)
                tangent(j, 4, k) = lim*dn(2, 2)
                tangent(j, 7, k) = lim*dn(1, 3)
                tangent(j, 8, k) = lim*dn(2, 3)
                tangent(j, 9, k) = lim*dn(1, 4)
                tangent(j, 10, k) = lim*dn(2, 4)
                tangent(j, 5:6, k) = mu(j)*kn(j)*(nv + r1*dn(:, 6))
                tangent(j, 11:12, k) = mu(j)*kn(j)*r1*dn(:, 5)
            end do
        end do
    end subroutine friction2d_march

    !> A 2-D sample after a start slider outside the limit (|z0| = rz > r0, z0 = rz e):
    !> it slides radially onto the limit at the previous sample, z0 -> r0 e
    !> (d z0 -> P d z0 + e d r0, P = (r0/rz) (I - e e^T)), then steps exactly (slip2d_step).
    !> f: the force at the sample (the slider is u - f/kt); tg: its tangent as in
    !> friction2d_march (G = G' P, c = c' + mu kn r1 dn/dz0 e from the step's own G', c').
    pure subroutine outside_step(e, rz, du, r0, r1, kt, mukn, f, tg)
        real(wp), intent(in) :: e(2), rz, du(2), r0, r1  !! direction, |z0|, motion, radii, m
        real(wp), intent(in) :: kt, mukn                 !! kt, mu kn, N/m
        real(wp), intent(out) :: f(2)                    !! tangential force, N
        real(wp), intent(out) :: tg(12)                  !! tangent, see friction2d_march
        real(wp) :: pm(2, 2), zp(2), nv(2), dn(2, 6)
        logical :: slip
        pm = r0/rz*reshape([1.0_wp - e(1)**2, -e(1)*e(2), -e(1)*e(2), 1.0_wp - e(2)**2], [2, 2])
        zp = r0*e
        tg = 0.0_wp
        call slip2d_step(zp, du, r0, r1, slip, nv, dn)
        if (.not. slip) then                ! sticks from the slid slider
            f = kt*(zp + du)
            tg(1:4) = kt*reshape(pm, [4])
            tg(7:10) = kt*[1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp]
            tg(11:12) = mukn*e
            return
        end if
        f = kt*r1*nv
        tg(1:4) = kt*r1*reshape(matmul(dn(:, 1:2), pm), [4])
        tg(7:10) = kt*r1*reshape(dn(:, 3:4), [4])
        tg(5:6) = mukn*(nv + r1*dn(:, 6))
        tg(11:12) = mukn*r1*(dn(:, 5) + matmul(dn(:, 1:2), e))
    end subroutine outside_step

    !> Exact slider update of the 2-D law along one sample interval on which the relative
    !> displacement moves linearly by du and the slip radius (friction limit / kt) changes
    !> linearly from r0 > 0 to r1 > 0; z0 = u - w at the start, |z0| <= r0.
    !> Stick while g(theta) = |z0 + theta du|^2 - (r0 + theta dr)^2 <= 0; slip from the
    !> first theta_a in [0, 1] where g crosses zero upwards (0 if z0 is on the limit and
    !> moves out). While slipping z = r n with n' = (I - n n^T) u'/r: the angle psi between
    !> n and the motion e = du/|du| obeys d(ln tan(psi/2)) = -|du| dtheta/r, so over the
    !> rest of the interval tan(psi_1/2) = tan(psi_a/2) exp(-S), S = |du| (1 - theta_a)
    !> ln(r1/r_a)/(r1 - r_a). The slip rate n.du - dr grows as psi shrinks, so slip, once
    !> started, lasts to the end of the interval. slip: the interval slips; n1: the slip
    !> direction at its end (the slider is u_end - r1 n1); dn(:, i): d n1 / d input i,
    !> inputs (z0(1), z0(2), du(1), du(2), r0, r1).
    pure subroutine slip2d_step(z0, du, r0, r1, slip, n1, dn)
        real(wp), intent(in) :: z0(2), du(2), r0, r1
        logical, intent(out) :: slip
        real(wp), intent(out) :: n1(2), dn(2, 6)
        !> |z0|^2 within this of r0^2: z0 on the limit (the previous sample slipped)
        real(wp), parameter :: ON_LIMIT = 1.0e-12_wp
        !> relative slip rate at the onset below which the interval is taken as stuck
        real(wp), parameter :: GRAZE = 1.0e-8_wp
        real(wp) :: dr, g0, b, a, disc, theta, y(2), rho, na(2), ra, lam, s, e(2), c
        real(wp) :: el, phi, phia, phi1, sx, q, p, d, nvec(2), eye(2, 2)
        real(wp) :: gth(6), dy(2, 6), dna(2, 6), dra(6), de(2, 6), ds(6), dc(6), dl(6)
        real(wp) :: dsx(6), dq(6), dnv(2, 6), dd(6)
        logical :: fixed
        integer(ip) :: i
        slip = .false.
        n1 = 0.0_wp
        dn = 0.0_wp
        eye = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
        dr = r1 - r0
        g0 = min(dot_product(z0, z0) - r0**2, 0.0_wp)
        if (g0 >= -ON_LIMIT*r0**2) g0 = 0.0_wp
        b = dot_product(z0, du) - r0*dr
        a = dot_product(du, du) - dr**2
        disc = b*b - a*g0
        if (disc < 0.0_wp) return
        fixed = .false.
        if (b >= 0.0_wp) then
            if (b + sqrt(disc) > 0.0_wp) then
                theta = -g0/(b + sqrt(disc))
            else if (a > 0.0_wp) then
                theta = 0.0_wp
            else
                return
            end if
            fixed = g0 == 0.0_wp
        else
            if (a <= 0.0_wp) return
            theta = (-b + sqrt(disc))/a
        end if
        if (theta > 1.0_wp) return
        y = z0 + theta*du
        rho = norm2(y)
        if (rho <= 0.0_wp) return
        na = y/rho
        ra = r0 + theta*dr
        lam = dot_product(na, du) - dr
        ! touches the limit without crossing it; grazing (lam ~ 0) slips by O(lam^2) while
        ! d theta ~ 1/lam: taken as stick below GRAZE
        if (lam <= GRAZE*(norm2(du) + abs(dr))) return
        slip = .true.
        ! derivatives with respect to (z0, du, r0, r1)
        gth = 0.0_wp
        if (.not. fixed) then        ! g(theta) = 0: d theta = -(na.dy|theta - dra|theta)/lam
            gth(1:2) = -na/lam
            gth(3:4) = -theta*na/lam
            gth(5) = (1.0_wp - theta)/lam
            gth(6) = theta/lam
        end if
        dy = 0.0_wp
        dy(:, 1:2) = eye
        dy(:, 3:4) = theta*eye
        do i = 1, 6
            dy(:, i) = dy(:, i) + du*gth(i)
        end do
        dna = matmul(eye - outer(na, na), dy)/rho
        dra = dr*gth
        dra(5) = dra(5) + 1.0_wp - theta
        dra(6) = dra(6) + theta
        call log_ratio(ra, r1, phi, phia, phi1)
        s = norm2(du)
        if (s <= 0.0_wp) then        ! no motion: n stays (turns by (1-theta) phi per du)
            n1 = na
            dn = dna
            dn(:, 3:4) = dn(:, 3:4) + (1.0_wp - theta)*phi*(eye - outer(na, na))
            return
        end if
        e = du/s
        de = 0.0_wp
        de(:, 3:4) = (eye - outer(e, e))/s
        ds = 0.0_wp
        ds(3:4) = e
        c = dot_product(na, e)
        dc = matmul(e, dna) + matmul(na, de)
        el = (1.0_wp - theta)*s
        dl = -s*gth + (1.0_wp - theta)*ds
        sx = el*phi
        dsx = phi*dl + el*phia*dra
        dsx(6) = dsx(6) + el*phi1
        q = exp(-sx)
        dq = -q*dsx
        p = (1.0_wp + c) - (1.0_wp - c)*q*q
        d = (1.0_wp + c) + (1.0_wp - c)*q*q
        nvec = p*e + 2.0_wp*q*(na - c*e)
        n1 = nvec/d
        dnv = outer((1.0_wp - q)**2*e, dc) &
              + outer(2.0_wp*(na - c*e) - 2.0_wp*(1.0_wp - c)*q*e, dq) &
              + 2.0_wp*q*dna + (p - 2.0_wp*q*c)*de
        dd = (1.0_wp - q*q)*dc + 2.0_wp*(1.0_wp - c)*q*dq
        dn = (dnv - outer(n1, dd))/d
    contains
        pure function outer(x, z) result(o)
            real(wp), intent(in) :: x(:), z(:)
            real(wp) :: o(size(x), size(z))
            integer(ip) :: ii
            do ii = 1, size(z)
                o(:, ii) = x*z(ii)
            end do
        end function outer
    end subroutine slip2d_step

    !> phi = ln(r1/ra)/(r1 - ra) (1/ra at r1 = ra) and its partial derivatives, ra, r1 > 0.
    pure subroutine log_ratio(ra, r1, phi, phia, phi1)
        real(wp), intent(in) :: ra, r1
        real(wp), intent(out) :: phi, phia, phi1
        real(wp) :: x, h, hp
        x = r1/ra - 1.0_wp
        if (abs(x) < 1.0e-2_wp) then      ! h = ln(1 + x)/x and h' by their series
            h = 1.0_wp + x*(-0.5_wp + x*(1.0_wp/3 + x*(-0.25_wp + x*(0.2_wp - x/6))))
            hp = -0.5_wp + x*(2.0_wp/3 + x*(-0.75_wp + x*(0.8_wp - x*5.0_wp/6)))
        else
            h = log(1.0_wp + x)/x
            hp = (x/(1.0_wp + x) - log(1.0_wp + x))/x**2
        end if
        phi = h/ra
        phi1 = hp/ra**2
        phia = -h/ra**2 - hp*r1/ra**3
    end subroutine log_ratio

    !> Positions the slider of an element with normal load variation follows: u, except at
    !> an open sample k-1 followed by a closed sample k, where it is the re-contact point
    !> u_{k-1} + theta (u_k - u_{k-1}), theta = g_{k-1}/(g_{k-1} - g_k), g = n0 + kn v
    !> (sample 0 is sample N: the motion is periodic). The marches take uf in place of u:
    !> the forces at open samples are zero whatever u, and the slider leaves the last open
    !> sample where the contact closes.
    pure subroutine recontact_follow(u, v, kn, n0, uf)
        real(wp), intent(in) :: u(:, :)          !! (m, N) a tangential relative displ., m
        real(wp), intent(in) :: v(:, :)          !! (m, N) normal relative displacement, m
        real(wp), intent(in) :: kn(:), n0(:)     !! (m) N/m, N
        real(wp), intent(out) :: uf(:, :)        !! (m, N) positions for the march, m
        integer(ip) :: j, k, k1
        real(wp) :: g, g1, theta
        logical :: reclose
        do k = 1, size(u, 2)
            k1 = k + 1
            if (k == size(u, 2)) k1 = 1
            do j = 1, size(u, 1)
                g = n0(j) + kn(j)*v(j, k)
                g1 = n0(j) + kn(j)*v(j, k1)
                reclose = g <= 0.0_wp .and. g1 > 0.0_wp
                theta = g/merge(g - g1, -1.0_wp, reclose)
                uf(j, k) = merge(u(j, k) + theta*(u(j, k1) - u(j, k)), u(j, k), reclose)
            end do
        end do
    end subroutine recontact_follow

    !> Polynomial (cubic) spring f = k1 u + k3 u^3 and its derivative.
    elemental subroutine cubic_spring(u, k1, k3, f, dfdu)
        real(wp), intent(in) :: u, k1, k3  !! m, N/m, N/m^3
        real(wp), intent(out) :: f, dfdu   !! N, N/m
        f = u*(k1 + k3*u*u)
        dfdu = k1 + 3.0_wp*k3*u*u
    end subroutine cubic_spring
end module frirom_contact
