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
        real(wp) :: tg(1, 6, 4), uf1(1, 4), uf2(1, 4)
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

    !> 2-D element along an elliptic orbit with normal load variation: at every slip
    !> sample |f_t| = mu f_n along the trial direction, at every open sample f = 0; motion in
    !> one plane (u2 = 0) gives the 1-D element's forces, states and sliders.
    subroutine friction2d_limit_and_in_plane()
        integer(ip), parameter :: n = 64
        real(wp), parameter :: kt = 1.0e5_wp, kn = 0.8e5_wp, mu = 0.4_wp, n0 = 60.0_wp
        real(wp) :: u1(1, n), u2(1, n), v(1, n), w(1, 2), wp_(1, 2), f1(1, n), f2(1, n)
        real(wp) :: fn(1, n), tg(1, 6, n), w1(1), g(1, n), gn(1, n), dv(1, n), tau, t1, t2
        integer(ip) :: state(1, n), s1(1, n), k
        do k = 1, n
            tau = 2.0_wp*pi*real(k - 1, wp)/real(n, wp)
            u1(1, k) = 1.0e-3_wp*cos(tau)
            u2(1, k) = 0.7e-3_wp*sin(tau)
            v(1, k) = 1.2e-3_wp*sin(tau) + 0.3e-3_wp*cos(2*tau)
        end do
        w = 0.0_wp
        do k = 1, n
            ! one sample at a time, to know the slider before each sample
            wp_ = w
            call friction2d_march(u1(:, k:k), u2(:, k:k), v(:, k:k), [kt], [kn], [mu], [n0], &
                                  w, f1(:, k:k), f2(:, k:k), fn(:, k:k), state(:, k:k), &
                                  tg(:, :, k:k))
            t1 = kt*(u1(1, k) - wp_(1, 1))
            t2 = kt*(u2(1, k) - wp_(1, 2))
            select case (state(1, k))
            case (STATE_SLIP)
                call check(abs(hypot(f1(1, k), f2(1, k)) - mu*fn(1, k)) < 1.0e-12_wp*n0, &
                           '2-D slip: |f_t| = mu f_n')
                call check(abs(f1(1, k)*t2 - f2(1, k)*t1) < 1.0e-12_wp*n0*hypot(t1, t2) &
                           .and. f1(1, k)*t1 + f2(1, k)*t2 > 0.0_wp, &
                           '2-D slip: force along the trial force')
            case (STATE_STICK)
                call check(abs(f1(1, k) - t1) + abs(f2(1, k) - t2) < 1.0e-12_wp*n0 .and. &
                           hypot(t1, t2) <= mu*fn(1, k), '2-D stick: f = kt (u - w) inside')
            case default
                call check(f1(1, k) == 0.0_wp .and. f2(1, k) == 0.0_wp .and. &
                           fn(1, k) == 0.0_wp .and. w(1, 1) == u1(1, k) .and. &
                           w(1, 2) == u2(1, k), '2-D lift-off: no force, slider on contact')
            end select
        end do
        call check(count(state == STATE_SLIP) > 2 .and. count(state == STATE_STICK) > 2 .and. &
                   count(state == STATE_LIFTOFF) > 2, '2-D orbit: all three states')
        ! in one plane: the 1-D element
        u2 = 0.0_wp
        w = 0.0_wp
        w1 = 0.0_wp
        call friction2d_march(u1, u2, v, [kt], [kn], [mu], [n0], w, f1, f2, fn, state, tg)
        call friction1d_march(u1, v, [kt], [kn], [mu], [n0], w1, g, gn, s1, dv)
        call check(near(f1(1, :), g(1, :), 1.0e-12_wp*n0) .and. all(f2 == 0.0_wp) .and. &
                   near(fn(1, :), gn(1, :), 1.0e-12_wp*n0) .and. all(state == s1) .and. &
                   abs(w(1, 1) - w1(1)) < 1.0e-15_wp, '2-D in one plane = 1-D element')
    end subroutine friction2d_limit_and_in_plane

    !> The 2-D slip tangent A (d f_t/d u), b (d f_t/d v) and -A (d f_t / d w, the slider
    !> before the sample) against central differences of a one-sample march, at every
    !> sample of the orbit above; kt I and 0 in stick, 0 in lift-off.
    subroutine friction2d_derivatives()
        integer(ip), parameter :: n = 64
        real(wp), parameter :: kt = 1.0e5_wp, kn = 0.8e5_wp, mu = 0.4_wp, n0 = 60.0_wp
        real(wp), parameter :: h = 1.0e-9_wp, p(4) = [kt, kn, mu, n0]
        real(wp) :: y(5), yh(5), w(2), f(2), tg0(6), tg(6), fd(2, 5), ref(2, 5)
        real(wp) :: fp(2), fm(2), tau
        integer(ip) :: k, i, s, sp, sm, tested(0:2)
        w = 0.0_wp
        tested = 0
        do k = 1, n
            tau = 2.0_wp*pi*real(k - 1, wp)/real(n, wp)
            ! y = (u1, u2, v, w1, w2): the sample's motion and the slider before it
            y = [1.0e-3_wp*cos(tau), 0.7e-3_wp*sin(tau), &
                 1.2e-3_wp*sin(tau) + 0.3e-3_wp*cos(2*tau), w]
            call f2d_sample(y, p, f, s, tg0, w)
            do i = 1, 5
                yh = y
                yh(i) = y(i) + h
                call f2d_sample(yh, p, fp, sp, tg)
                yh(i) = y(i) - h
                call f2d_sample(yh, p, fm, sm, tg)
                if (sp /= s .or. sm /= s) exit
                fd(:, i) = (fp - fm)/(2*h)
            end do
            if (i <= 5) cycle
            ref = 0.0_wp
            select case (s)
            case (STATE_SLIP)
                ref(:, 1:2) = reshape(tg0(1:4), [2, 2])
                ref(:, 3) = tg0(5:6)
                ref(:, 4:5) = -ref(:, 1:2)
            case (STATE_STICK)
                ref(1, 1) = kt
                ref(2, 2) = kt
                ref(1, 4) = -kt
                ref(2, 5) = -kt
                call check(all(tg0 == 0.0_wp), '2-D stick: zero slip tangent')
            end select
            call check(maxval(abs(fd - ref)) < 1.0e-6_wp*kt, &
                       '2-D derivatives = central differences')
            tested(s) = tested(s) + 1
        end do
        call check(all(tested > 2), '2-D derivatives: samples in stick, slip and lift-off')
    end subroutine friction2d_derivatives

    !> One sample of the 2-D element: y = (u1, u2, v, w1, w2) in m.
    subroutine f2d_sample(y, p, f, state, tangent, w_end)
        real(wp), intent(in) :: y(5)      !! motion of the sample and slider before it, m
        real(wp), intent(in) :: p(4)      !! kt, kn (N/m), mu, n0 (N)
        real(wp), intent(out) :: f(2)     !! tangential force, N
        integer(ip), intent(out) :: state  !! STATE_*
        real(wp), intent(out) :: tangent(6)  !! slip tangent, see friction2d_march
        real(wp), intent(out), optional :: w_end(2)  !! slider after the sample, m
        real(wp) :: ws(1, 2), f1(1, 1), f2(1, 1), fn(1, 1), tg(1, 6, 1)
        integer(ip) :: st(1, 1)
        ws(1, :) = y(4:5)
        call friction2d_march(reshape(y(1:1), [1, 1]), reshape(y(2:2), [1, 1]), &
                              reshape(y(3:3), [1, 1]), p(1:1), p(2:2), p(3:3), p(4:4), ws, &
                              f1, f2, fn, st, tg)
        f = [f1(1, 1), f2(1, 1)]
        state = st(1, 1)
        tangent = tg(1, :, 1)
        if (present(w_end)) w_end = ws(1, :)
    end subroutine f2d_sample

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
