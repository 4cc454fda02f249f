!> frirom_contact against closed forms and central differences.
!>
!> Closed forms: short hand-worked sample sequences through every branch of each law
!> (stick, slip, lift-off, reclosing unstretched, an initial gap), the Jenkins hysteresis
!> loop under u = A cos at every sample, the friction limit |f_t| = mu f_n at every slip
!> sample of the 2-D element, and the cubic spring. Tolerances are round-off: the laws are
!> a few flops per sample, so 1e-12 of the force scale.
!> Derivatives: the same-sample derivatives the AFT Jacobian is built from (dft_dv of the
!> 1-D element, the slip tangent of the 2-D element, the cubic stiffness) against central
!> differences. Within one branch the 1-D law is linear in (u, v), so the difference is exact
!> to round-off (1e-7 of kt); the 2-D slip force is smooth in u, with an O(h^2) truncation
!> error far below the 1e-6 bound at h = 1e-9 of a 1 mm motion. Samples where the step
!> would change the branch are skipped (the law has a kink there).
program test_contact
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done
    use frirom_contact
    implicit none
    real(wp), parameter :: pi = acos(-1.0_wp)

    call jenkins_hand_sequence()
    call jenkins_hysteresis_loop()
    call friction1d_hand_sequence()
    call friction1d_initial_gap()
    call friction1d_derivatives()
    call friction2d_hand_sequence()
    call friction2d_limit_and_in_plane()
    call friction2d_derivatives()
    call cubic_closed_form()
    call check_done('test_contact')

contains

    !> True when |a - b| <= tol elementwise.
    pure logical function near(a, b, tol)
        real(wp), intent(in) :: a(:), b(:)  !! (n) values to compare
        real(wp), intent(in) :: tol          !! absolute tolerance
        near = all(abs(a - b) <= tol)
    end function near

    !> Jenkins, kt = 100 N/m, mu fn0 = 5 N (slip beyond 0.05 m of stretch), by hand:
    !> stick, slip (slider moves), stick again from the moved slider, slip the other way.
    !> A second element with fn0 = 0 is open all along: no force, slider on the contact point.
    subroutine jenkins_hand_sequence()
        real(wp) :: u(2, 4), w(2), ft(2, 4)
        integer(ip) :: state(2, 4)
        u(1, :) = [0.02_wp, 0.08_wp, 0.05_wp, -0.10_wp]
        u(2, :) = [0.01_wp, 0.30_wp, -0.20_wp, 0.07_wp]
        w = [0.0_wp, 0.5_wp]
        call jenkins_march(u, [100.0_wp, 100.0_wp], [0.5_wp, 0.5_wp], [10.0_wp, 0.0_wp], &
                           w, ft, state)
        ! 1: t = 2 <= 5 stick; 2: t = 8 > 5 slip, w = 0.08 - 5/100 = 0.03;
        ! 3: t = 100 (0.05 - 0.03) = 2 stick; 4: t = -13 slip, w = -0.10 + 0.05 = -0.05
        call check(near(ft(1, :), [2.0_wp, 5.0_wp, 2.0_wp, -5.0_wp], 1.0e-12_wp), &
                   'Jenkins hand sequence: forces')
        call check(all(state(1, :) == [STATE_STICK, STATE_SLIP, STATE_STICK, STATE_SLIP]), &
                   'Jenkins hand sequence: states')
        call check(abs(w(1) + 0.05_wp) < 1.0e-14_wp, 'Jenkins hand sequence: end slider')
        call check(all(ft(2, :) == 0.0_wp), 'Jenkins fn0 = 0: no force')
        call check(all(state(2, :) == STATE_LIFTOFF), 'Jenkins fn0 = 0: lift-off state')
        call check(w(2) == u(2, 4), 'Jenkins fn0 = 0: slider follows the contact point')
    end subroutine jenkins_hand_sequence

    !> Jenkins under u = A cos(tau), A > mu fn0 / kt, from a cold slider: the element slips
    !> at the first sample, so the first period is already the closed loop
    !> f = max(fs - kt (A - u), -fs) while u falls, min(-fs + kt (u + A), fs) while it rises
    !> (fs = mu fn0); slip exactly where the loop sits on +-fs, and a second period repeats.
    subroutine jenkins_hysteresis_loop()
        integer(ip), parameter :: n = 64
        real(wp), parameter :: kt = 1.0e5_wp, mu = 0.3_wp, fn0 = 100.0_wp, amp = 1.0e-3_wp
        real(wp) :: u(1, n), ft(1, n), ft2(1, n), w(1), closed(n), tau, fs
        integer(ip) :: state(1, n), state2(1, n), k
        fs = mu*fn0
        do k = 1, n
            tau = 2.0_wp*pi*real(k - 1, wp)/real(n, wp)
            u(1, k) = amp*cos(tau)
            if (2*(k - 1) <= n) then
                closed(k) = max(fs - kt*(amp - u(1, k)), -fs)
            else
                closed(k) = min(-fs + kt*(u(1, k) + amp), fs)
            end if
        end do
        w = 0.0_wp
        call jenkins_march(u, [kt], [mu], [fn0], w, ft, state)
        call check(near(ft(1, :), closed, 1.0e-12_wp*fs), 'Jenkins loop: closed form')
        call check(all((state(1, :) == STATE_SLIP) .eqv. (abs(closed) == fs)), &
                   'Jenkins loop: slip exactly on the friction limit')
        call check(count(state(1, :) == STATE_STICK) > n/8, 'Jenkins loop: sticks at reversals')
        call check(abs(w(1) - (u(1, n) - ft(1, n)/kt)) < 1.0e-15_wp, &
                   'Jenkins loop: end slider u - f/kt after slip')
        call jenkins_march(u, [kt], [mu], [fn0], w, ft2, state2)
        call check(near(ft2(1, :), ft(1, :), 1.0e-12_wp*fs) .and. all(state2 == state), &
                   'Jenkins loop: the second period repeats the first')
    end subroutine jenkins_hysteresis_loop

    !> 1-D element with normal load variation, kt = 100 N/m, kn = 200 N/m, mu = 0.5,
    !> n0 = 10 N, by hand: stick; the normal load drops under the stuck force (slip at the
    !> lower limit); lift-off (slider on the contact point); reclosing unstretched at the
    !> interpolated re-contact point; stick; slip the other way under a raised normal load.
    subroutine friction1d_hand_sequence()
        real(wp) :: u(1, 6), v(1, 6), w(1), ft(1, 6), fn(1, 6), dv(1, 6), uf(1, 6)
        integer(ip) :: state(1, 6)
        u(1, :) = [0.02_wp, 0.02_wp, 0.0_wp, 0.03_wp, -0.05_wp, -0.2_wp]
        v(1, :) = [0.0_wp, -0.04_wp, -0.06_wp, 0.0_wp, 0.05_wp, 0.05_wp]
        w = 0.0_wp
        call recontact_follow(u, v, [200.0_wp], [10.0_wp], uf)
        call check(near(uf(1, :) - u(1, :), [0.0_wp, 0.0_wp, 0.005_wp, 0.0_wp, 0.0_wp, 0.0_wp], &
                        1.0e-15_wp), '1-D hand sequence: slider follows the re-contact point')
        call friction1d_march(uf, v, [100.0_wp], [200.0_wp], [0.5_wp], [10.0_wp], w, ft, fn, &
                              state, dv)
        ! fn = max(10 + 200 v, 0) = 10, 2, 0, 10, 20, 20; limits 5, 1, 0, 5, 10, 10
        call check(near(fn(1, :), [10.0_wp, 2.0_wp, 0.0_wp, 10.0_wp, 20.0_wp, 20.0_wp], &
                        1.0e-12_wp), '1-D hand sequence: normal force max(n0 + kn v, 0)')
        ! 1: t = 2 stick; 2: t = 2 > 1 slip, w = 0.01; 3: open; n0 + kn v goes -2 -> 10 to
        ! sample 4, zero at 1/6 of the step: w = 0 + 0.03/6 = 0.005 (uf above);
        ! 4: t = 100 (0.03 - 0.005) = 2.5 stick (unstretched from where it touched down);
        ! 5: t = -5.5 stick; 6: t = -20.5 slip at -10, w = -0.2 + 0.1 = -0.1
        call check(near(ft(1, :), [2.0_wp, 1.0_wp, 0.0_wp, 2.5_wp, -5.5_wp, -10.0_wp], &
                        1.0e-12_wp), '1-D hand sequence: tangential force')
        call check(all(state(1, :) == [STATE_STICK, STATE_SLIP, STATE_LIFTOFF, STATE_STICK, &
                                       STATE_STICK, STATE_SLIP]), '1-D hand sequence: states')
        call check(abs(w(1) + 0.1_wp) < 1.0e-14_wp, '1-D hand sequence: end slider')
        ! d f_t/d v = sign(t) mu kn at slip samples, 0 elsewhere
        call check(near(dv(1, :), [0.0_wp, 100.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, -100.0_wp], &
                        1.0e-12_wp), '1-D hand sequence: dft_dv')
    end subroutine friction1d_hand_sequence

    !> n0 < 0 is an initial gap g0 = -n0/kn = 0.02 m: open below it, pressed beyond it.
    subroutine friction1d_initial_gap()
        real(wp) :: u(1, 3), v(1, 3), w(1), ft(1, 3), fn(1, 3), dv(1, 3)
        integer(ip) :: state(1, 3)
        u(1, :) = [0.01_wp, 0.01_wp, 0.012_wp]
        v(1, :) = [0.01_wp, 0.03_wp, 0.03_wp]
        w = 0.0_wp
        call friction1d_march(u, v, [100.0_wp], [200.0_wp], [0.5_wp], [-4.0_wp], w, ft, fn, &
                              state, dv)
        ! fn = max(-4 + 200 v, 0) = 0, 2, 2; the contact closes at u = 0.01 unstretched
        call check(near(fn(1, :), [0.0_wp, 2.0_wp, 2.0_wp], 1.0e-12_wp), 'gap: normal force')
        call check(near(ft(1, :), [0.0_wp, 0.0_wp, 0.2_wp], 1.0e-12_wp), 'gap: tangential')
        call check(all(state(1, :) == [STATE_LIFTOFF, STATE_STICK, STATE_STICK]), 'gap: states')
    end subroutine friction1d_initial_gap

    !> Same-sample derivatives of the 1-D element along a cycle with stick, slip and
    !> lift-off against central differences in u(k) and v(k): kt / 0 / 0 in u, dft_dv in v,
    !> kn / 0 in the normal force.
    subroutine friction1d_derivatives()
        integer(ip), parameter :: n = 64
        real(wp), parameter :: kt = 1.0e5_wp, kn = 0.8e5_wp, mu = 0.4_wp, n0 = 60.0_wp
        real(wp), parameter :: h = 1.0e-9_wp, p(4) = [kt, kn, mu, n0]
        real(wp) :: u(1, n), v(1, n), w(1), ft(1, n), fn(1, n), dv(1, n), x(1, n)
        real(wp) :: fp(2), fm(2), gp(2), gm(2), d_u, d_v, d_n, tau
        integer(ip) :: state(1, n), s(4), k, tested(0:2)
        do k = 1, n
            tau = 2.0_wp*pi*real(k - 1, wp)/real(n, wp)
            u(1, k) = 1.0e-3_wp*cos(tau) + 0.2e-3_wp*sin(2*tau)
            v(1, k) = 1.2e-3_wp*sin(tau) + 0.3e-3_wp*cos(2*tau)
        end do
        ! start from the closed cycle's slider (march twice)
        w = 0.0_wp
        call friction1d_march(u, v, [kt], [kn], [mu], [n0], w, ft, fn, state, dv)
        call friction1d_march(u, v, [kt], [kn], [mu], [n0], w, ft, fn, state, dv)
        ! the first march closed the cycle: w is where the second started and ended
        tested = 0
        do k = 1, n
            x = u
            x(1, k) = u(1, k) + h
            call f1d_sample(x, v, p, w, k, fp, s(1))
            x(1, k) = u(1, k) - h
            call f1d_sample(x, v, p, w, k, fm, s(2))
            x = v
            x(1, k) = v(1, k) + h
            call f1d_sample(u, x, p, w, k, gp, s(3))
            x(1, k) = v(1, k) - h
            call f1d_sample(u, x, p, w, k, gm, s(4))
            if (any(s /= state(1, k))) cycle
            d_u = (fp(1) - fm(1))/(2*h)
            d_v = (gp(1) - gm(1))/(2*h)
            d_n = (gp(2) - gm(2))/(2*h)
            select case (state(1, k))
            case (STATE_STICK)
                call check(abs(d_u - kt) < 1.0e-7_wp*kt, '1-D stick: d ft/du = kt')
                call check(abs(d_n - kn) < 1.0e-7_wp*kt, '1-D stick: d fn/dv = kn')
            case (STATE_SLIP)
                call check(abs(d_u) < 1.0e-7_wp*kt, '1-D slip: d ft/du = 0')
                call check(abs(d_n - kn) < 1.0e-7_wp*kt, '1-D slip: d fn/dv = kn')
            case default
                call check(abs(d_u) + abs(d_n) < 1.0e-7_wp*kt, '1-D lift-off: no derivative')
            end select
            call check(abs(d_v - dv(1, k)) < 1.0e-7_wp*kt, '1-D: dft_dv = central difference')
            tested(state(1, k)) = tested(state(1, k)) + 1
        end do
        call check(all(tested > 2), '1-D derivatives: samples in stick, slip and lift-off')
    end subroutine friction1d_derivatives

    !> Forces and state at sample k of a 1-D march over (1, N) samples from slider w.
    subroutine f1d_sample(u, v, p, w, k, f, state_k)
        real(wp), intent(in) :: u(:, :), v(:, :)  !! (1, N) tangential, normal motion, m
        real(wp), intent(in) :: p(4)              !! kt, kn (N/m), mu, n0 (N)
        real(wp), intent(in) :: w(1)              !! slider at the start, m
        integer(ip), intent(in) :: k              !! the sample
        real(wp), intent(out) :: f(2)             !! f_t, f_n at sample k, N
        integer(ip), intent(out) :: state_k       !! STATE_* at sample k
        real(wp) :: ws(1), ft(1, size(u, 2)), fn(1, size(u, 2)), dv(1, size(u, 2))
        integer(ip) :: state(1, size(u, 2))
        ws = w
        call friction1d_march(u, v, p(1:1), p(2:2), p(3:3), p(4:4), ws, ft, fn, state, dv)
        f = [ft(1, k), fn(1, k)]
        state_k = state(1, k)
    end subroutine f1d_sample

    !> 2-D element, kt = 100 N/m, kn = 200 N/m, mu = 0.5, n0 = 10 N, by hand: stick inside
    !> the circle; slip on it along the trial force; lift-off; reclosing unstretched at the
    !> interpolated re-contact point.
    subroutine friction2d_hand_sequence()
        real(wp) :: u1(1, 4), u2(1, 4), v(1, 4), w(1, 2), f1(1, 4), f2(1, 4), fn(1, 4)
        real(wp) :: tg(1, 12, 4), uf1(1, 4), uf2(1, 4)
        integer(ip) :: state(1, 4)
        u1(1, :) = [0.03_wp, 0.06_wp, 0.03_wp, 0.0_wp]
        u2(1, :) = [0.04_wp, 0.08_wp, 0.04_wp, 0.04_wp]
        v(1, :) = [0.01_wp, 0.0_wp, -0.06_wp, 0.0_wp]
        w = 0.0_wp
        call recontact_follow(u1, v, [200.0_wp], [10.0_wp], uf1)
        call recontact_follow(u2, v, [200.0_wp], [10.0_wp], uf2)
        call friction2d_march(uf1, uf2, v, [100.0_wp], [200.0_wp], [0.5_wp], [10.0_wp], w, &
                              f1, f2, fn, state, tg)
        ! 1: limit 6, t = (3, 4), |t| = 5 stick; 2: limit 5, t = (6, 8), |t| = 10 slip at
        ! 5 (0.6, 0.8), w = u - f/kt = (0.03, 0.04); 3: open, w = u = (0.03, 0.04);
        ! 4: n0 + kn v goes -2 -> 10, zero at 1/6 of the step: w = (0.03 - 0.03/6, 0.04),
        ! t = 100 (0 - 0.025, 0.04 - 0.04) = (-2.5, 0) stick
        call check(near(f1(1, :), [3.0_wp, 3.0_wp, 0.0_wp, -2.5_wp], 1.0e-12_wp) .and. &
                   near(f2(1, :), [4.0_wp, 4.0_wp, 0.0_wp, 0.0_wp], 1.0e-12_wp), &
                   '2-D hand sequence: forces')
        call check(near(fn(1, :), [12.0_wp, 10.0_wp, 0.0_wp, 10.0_wp], 1.0e-12_wp), &
                   '2-D hand sequence: normal force')
        call check(all(state(1, :) == [STATE_STICK, STATE_SLIP, STATE_LIFTOFF, STATE_STICK]), &
                   '2-D hand sequence: states')
        call check(near(w(1, :), [0.025_wp, 0.04_wp], 1.0e-14_wp), '2-D hand sequence: slider')
        call check(all(tg(1, :, [1, 3, 4]) == 0.0_wp), '2-D: no slip tangent off slip samples')
    end subroutine friction2d_hand_sequence

    !> 2-D element along an elliptic orbit with normal load variation, one period marched:
    !> the slider before each sample follows from the forces (w = u - f/kt at closed
    !> samples, u at open ones). At every stick sample f = kt (u - w) within mu f_n; at
    !> every slip sample |f_t| = mu f_n; at every open sample f = 0. The slip samples
    !> against an independent radial return over 4 096 substeps of each interval (u and
    !> the limit interpolated linearly; first order in the substep: 1e-3 of mu f_n). Motion
    !> in one plane (u2 = 0) gives the 1-D element's forces, states and sliders.
    subroutine friction2d_limit_and_in_plane()
        integer(ip), parameter :: n = 64, nsub = 4096
        real(wp), parameter :: kt = 1.0e5_wp, kn = 0.8e5_wp, mu = 0.4_wp, n0 = 60.0_wp
        real(wp) :: u1(1, n), u2(1, n), v(1, n), w(1, 2), f1(1, n), f2(1, n)
        real(wp) :: fn(1, n), tg(1, 12, n), w1(1), g(1, n), gn(1, n), dv(1, n), tau, t1, t2
        real(wp) :: wb(2), wr(2), wa(2), s, ui(2), li, ti(2), tni, fr(2, n)
        integer(ip) :: state(1, n), s1(1, n), k, kp, i
        do k = 1, n
            tau = 2.0_wp*pi*real(k - 1, wp)/real(n, wp)
            u1(1, k) = 1.0e-3_wp*cos(tau)
            u2(1, k) = 0.2e-3_wp*sin(tau)
            v(1, k) = 1.2e-3_wp*sin(tau) + 0.3e-3_wp*cos(2*tau)
        end do
        ! two periods: the second starts from the first's end slider
        w = 0.0_wp
        call friction2d_march(u1, u2, v, [kt], [kn], [mu], [n0], w, f1, f2, fn, state, tg)
        wa = w(1, :)
        call friction2d_march(u1, u2, v, [kt], [kn], [mu], [n0], w, f1, f2, fn, state, tg)
        wb = wa
        wr = wa
        do k = 1, n
            kp = merge(n, k - 1, k == 1)
            ! the reference: radial return along the interpolated interval kp -> k
            do i = 1, nsub
                s = real(i, wp)/real(nsub, wp)
                ui = [u1(1, kp) + s*(u1(1, k) - u1(1, kp)), u2(1, kp) + s*(u2(1, k) - u2(1, kp))]
                li = mu*max(n0 + kn*(v(1, kp) + s*(v(1, k) - v(1, kp))), 0.0_wp)
                if (li <= 0.0_wp) then
                    wr = ui
                    cycle
                end if
                ti = kt*(ui - wr)
                tni = hypot(ti(1), ti(2))
                if (tni > li) wr = ui - li*ti/(tni*kt)
            end do
            fr(:, k) = kt*([u1(1, k), u2(1, k)] - wr)
            t1 = kt*(u1(1, k) - wb(1))
            t2 = kt*(u2(1, k) - wb(2))
            select case (state(1, k))
            case (STATE_SLIP)
                call check(abs(hypot(f1(1, k), f2(1, k)) - mu*fn(1, k)) < 1.0e-12_wp*n0, &
                           '2-D slip: |f_t| = mu f_n')
                call check(maxval(abs([f1(1, k), f2(1, k)] - fr(:, k))) < 1.0e-3_wp*mu*n0, &
                           '2-D slip: force = finely substepped radial return')
            case (STATE_STICK)
                call check(abs(f1(1, k) - t1) + abs(f2(1, k) - t2) < 1.0e-12_wp*n0 .and. &
                           hypot(t1, t2) <= mu*fn(1, k)*(1.0_wp + 1.0e-12_wp), &
                           '2-D stick: f = kt (u - w) inside')
                call check(all(tg(1, :, k) == 0.0_wp), '2-D stick: zero slip tangent')
                call check(maxval(abs([f1(1, k), f2(1, k)] - fr(:, k))) < 1.0e-3_wp*mu*n0, &
                           '2-D stick: force = finely substepped radial return')
            case default
                call check(f1(1, k) == 0.0_wp .and. f2(1, k) == 0.0_wp .and. &
                           fn(1, k) == 0.0_wp, '2-D lift-off: no force')
            end select
            if (state(1, k) == STATE_LIFTOFF) then
                wb = [u1(1, k), u2(1, k)]
            else
                wb = [u1(1, k), u2(1, k)] - [f1(1, k), f2(1, k)]/kt
            end if
        end do
        call check(maxval(abs(wb - w(1, :))) < 1.0e-15_wp, '2-D: sliders follow the forces')
        call check(count(state == STATE_SLIP) > 2 .and. count(state == STATE_STICK) > 2 .and. &
                   count(state == STATE_LIFTOFF) > 2, '2-D orbit: all three states')
        ! in one plane: the 1-D element
        u2 = 0.0_wp
        w = 0.0_wp
        w1 = 0.0_wp
        call friction2d_march(u1, u2, v, [kt], [kn], [mu], [n0], w, f1, f2, fn, state, tg)
        call friction1d_march(u1, v, [kt], [kn], [mu], [n0], w1, g, gn, s1, dv)
        ! (the second period: a start slider outside the limit slides at different samples)
        call friction2d_march(u1, u2, v, [kt], [kn], [mu], [n0], w, f1, f2, fn, state, tg)
        call friction1d_march(u1, v, [kt], [kn], [mu], [n0], w1, g, gn, s1, dv)
        call check(near(f1(1, :), g(1, :), 1.0e-12_wp*n0) .and. all(f2 == 0.0_wp) .and. &
                   near(fn(1, :), gn(1, :), 1.0e-12_wp*n0) .and. all(state == s1) .and. &
                   abs(w(1, 1) - w1(1)) < 1.0e-15_wp, '2-D in one plane = 1-D element')
    end subroutine friction2d_limit_and_in_plane

    !> The exact slip step of the 2-D element (slip2d_step): its slip direction at the end
    !> of the interval against the radial return over 2^14 substeps (first order: 1e-3),
    !> and its derivatives d n1 / d (z0, du, r0, r1) against central differences (h = 1e-9
    !> of the 1e-3 scale: O(h^2) truncation, 1e-5 of the largest derivative). Cases: onset between
    !> the samples (|z0| < r0), on the limit (|z0| = r0, the previous interval slipped),
    !> a shrinking and a growing limit; inputs whose difference changes the branch are
    !> skipped.
    subroutine friction2d_derivatives()
        integer(ip), parameter :: ncase = 200, nsub = 16384
        real(wp), parameter :: h = 1.0e-9_wp
        real(wp) :: y(6), yh(6), n1(2), dn(2, 6), np(2), nm(2), dd(2, 6), fd(2, 6), ang
        real(wp) :: z(2), zr(2), s, ri, rho, rnd(6), dir(6, 6)
        logical :: slip, sp, sm, on
        integer(ip) :: c, i, tested(2), onlimit
        tested = 0
        onlimit = 0
        do c = 1, ncase
            call random_number(rnd)
            ang = 2.0_wp*pi*rnd(1)
            ! radii about 1e-3, |z0| inside (or on) r0, a motion of up to 2e-3
            y(5) = 1.0e-3_wp*(0.5_wp + rnd(2))
            y(6) = y(5)*(0.7_wp + 0.6_wp*rnd(3))
            rho = y(5)*merge(1.0_wp, rnd(4), mod(c, 2) == 0)
            y(1:2) = rho*[cos(ang), sin(ang)]
            y(3:4) = 2.0e-3_wp*[cos(2*pi*rnd(5)), sin(2*pi*rnd(5))]*(0.2_wp + rnd(6))
            call slip2d_step(y(1:2), y(3:4), y(5), y(6), slip, n1, dn)
            ! the reference path: radial return over substeps
            zr = y(1:2)
            do i = 1, nsub
                s = real(i, wp)/real(nsub, wp)
                ri = y(5) + s*(y(6) - y(5))
                z = zr + y(3:4)/real(nsub, wp)
                if (norm2(z) > ri) z = z*ri/norm2(z)
                zr = z
            end do
            if (.not. slip) then
                call check(norm2(zr - (y(1:2) + y(3:4))) < 1.0e-12_wp, &
                           '2-D step: a stuck interval is stuck along the path')
                cycle
            end if
            call check(norm2(zr/y(6) - n1) < 1.0e-3_wp, &
                       '2-D step: slip direction = finely substepped radial return')
            ! directions: the inputs; on the limit (a kink across it) z0 along it and z0
            ! with r0 together (the previous interval slipped: z0 = r0 n0)
            dir = 0.0_wp
            do i = 1, 6
                dir(i, i) = 1.0_wp
            end do
            on = abs(norm2(y(1:2)) - y(5)) < 1.0e-12_wp*y(5)
            if (on) then
                dir(:, 1) = [-y(2), y(1), 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]/norm2(y(1:2))
                dir(:, 2) = 0.0_wp
                dir(1:2, 5) = y(1:2)/norm2(y(1:2))
            end if
            do i = 1, 6
                yh = y + h*dir(:, i)
                call slip2d_step(yh(1:2), yh(3:4), yh(5), yh(6), sp, np, dd)
                yh = y - h*dir(:, i)
                call slip2d_step(yh(1:2), yh(3:4), yh(5), yh(6), sm, nm, dd)
                if (.not. (sp .and. sm)) exit
                fd(:, i) = (np - nm)/(2*h)
            end do
            if (i <= 6) cycle
            call check(maxval(abs(fd - matmul(dn, dir))) < 1.0e-5_wp*maxval(abs(dn)), &
                       '2-D step derivatives = central differences')
            if (on) onlimit = onlimit + 1
            tested(merge(1, 2, y(6) < y(5))) = tested(merge(1, 2, y(6) < y(5))) + 1
        end do
        call check(all(tested > 5) .and. onlimit > 5, &
                   '2-D step derivatives: on the limit, shrinking and growing limits')
    end subroutine friction2d_derivatives

    !> f = k1 u + k3 u^3 and f' = k1 + 3 k3 u^2 by hand; f' against central differences,
    !> whose error for a cubic is exactly k3 h^2.
    subroutine cubic_closed_form()
        real(wp), parameter :: k1 = 2.0_wp, k3 = 0.5_wp, h = 1.0e-4_wp
        real(wp) :: u(4), f(4), df(4), fp(4), fm(4), dummy(4)
        u = [-1.5_wp, 0.0_wp, 0.3_wp, 2.0_wp]
        call cubic_spring(u, k1, k3, f, df)
        call check(near(f, [-4.6875_wp, 0.0_wp, 0.6135_wp, 8.0_wp], 1.0e-14_wp), &
                   'cubic: f = k1 u + k3 u^3')
        call check(near(df, [5.375_wp, 2.0_wp, 2.135_wp, 8.0_wp], 1.0e-14_wp), &
                   'cubic: df/du = k1 + 3 k3 u^2')
        call cubic_spring(u + h, k1, k3, fp, dummy)
        call cubic_spring(u - h, k1, k3, fm, dummy)
        call check(near((fp - fm)/(2*h) - k3*h*h, df, 1.0e-9_wp), &
                   'cubic: df/du = central difference')
    end subroutine cubic_closed_form
end program test_contact
