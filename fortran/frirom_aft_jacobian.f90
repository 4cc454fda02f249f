!> AFT Jacobian: the analytical d(force harmonics)/d(displacement harmonics) of one
!> element, from the same-sample coefficient series (Toeplitz blocks built from run trig
!> sums) plus the terms of the slider anchors (1-D laws) or the propagated slider tangent
!> (2-D law). See frirom_aft for the method.
submodule (frirom_aft) frirom_aft_jacobian
    use frirom_fourier, only: run_trig_sums, toeplitz_add, segment_sum
    use frirom_contact, only: STATE_STICK, STATE_SLIP, STATE_LIFTOFF, friction2d_march
    implicit none

contains

    module procedure fill_series
        integer(ip) :: k
        associate (rout => plan%fp%rout, st => plan%state, par => plan%par)
            do k = 1, plan%fp%nsamp
                rout(1:m, k, 4) = merge(par(1:m, 1), 0.0_wp, st(1:m, k) == STATE_STICK)
                rout(1:m, k, 5) = merge(par(1:m, 2), 0.0_wp, st(1:m, k) /= STATE_LIFTOFF)
            end do
        end associate
    end procedure fill_series

    module procedure element_jacobian
        select case (law)
        case (LAW_JENKINS)
            call jac_friction1d(plan, j, p(1), .false., jac)
        case (LAW_NORMAL1D)
            call jac_friction1d(plan, j, p(1), .true., jac)
        case (LAW_NORMAL2D)
            call jac_friction2d(plan, j, p(1), w0j, jac)
        case (LAW_CUBIC)
            call jac_diagonal(plan, j, 2_ip, jac, 0_ip, 0_ip)
        end select
    end procedure element_jacobian

    !> Add the multiplication matrix of the series of element j in output slot `slot`
    !> (time samples, not transformed) to the block at (r0, c0) of jac.
    pure subroutine jac_diagonal(plan, j, slot, jac, r0, c0)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: j, slot, r0, c0
        real(wp), intent(inout) :: jac(:, :)
        real(wp) :: cm(0:2*plan%fp%nharm), sm(0:2*plan%fp%nharm)
        call run_trig_sums(plan%fp, plan%fp%rout(j, :, slot), cm, sm)
        call toeplitz_add(plan%fp%nharm, plan%fp%nsamp, cm, sm, jac, r0, c0)
    end subroutine jac_diagonal

    !> Jacobian of the Jenkins (normal = .false.) or 1-D normal-load element.
    !> Stick samples after anchor a: f_t(k) = kt (u_k - w_a), the slider w_a = u_a - f_t(a)/kt
    !> with f_t(a) = s mu (n0 + kn v_a) at a slip anchor, the re-contact point after a
    !> lift-off anchor (anchor_rows); slip: f_t(k) = s mu (n0 + kn v_k); f_n(k) = n0 + kn v_k
    !> in contact. The anchor of the first stick samples is the last anchor of the period,
    !> since the cycle is closed.
    subroutine jac_friction1d(plan, j, kt, normal, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        logical, intent(in) :: normal
        real(wp), intent(inout) :: jac(:, :)  !! (nd nc, nd nc)
        integer(ip) :: n, nc, nh, k, k0, a, last, first_end, r, nrun
        logical :: any_event
        real(wp) :: kn
        n = plan%fp%nsamp
        nc = plan%fp%ncoef
        nh = plan%fp%nharm
        kn = plan%par(j, 2)
        ! work arrays of the plan (no allocation per element)
        associate (st => plan%state, dtvs => plan%fp%rout(j, :, 4), &
                   ru => plan%jw(:, 2), rv => plan%jw(:, 3), ctu => plan%jt(:, 1), &
                   stu => plan%jt(:, 2), ctv => plan%jt(:, 3), stv => plan%jt(:, 4), &
                   cnv => plan%jt(:, 5), snv => plan%jt(:, 6))
            plan%jt = 0.0_wp
            ! One pass: runs of equal state (and slip sign) give the trig sums of the
            ! same-sample series kt [stick], d ft/dv [slip], kn [contact]. A stick run
            ! [k0, k-1] is a segment anchored at the slip or lift-off sample k0-1 before it;
            ! the run from sample 1 is anchored at the period's last such sample (the cycle
            ! is closed) and joins the run that ends at N: it is added last, when that
            ! anchor is known.
            any_event = .false.
            last = 0
            first_end = 0
            call run_starts(st(j, :), dtvs, normal, plan%events, nrun)
            do r = 1, nrun
                k0 = plan%events(r)
                k = plan%events(r + 1)
                select case (st(j, k0))
                case (STATE_STICK)
                    call add_run(kt, k0, k - 1, ctu, stu)
                    if (normal) call add_run(kn, k0, k - 1, cnv, snv)
                    if (k0 == 1) then
                        first_end = k - 1
                    else if (k - 1 < n .or. first_end == 0) then
                        call stick_segment(k0 - 1, k0, k - 1)
                    else
                        last = k0 - 1        ! the run up to N: joins the first one
                    end if
                case (STATE_SLIP)
                    any_event = .true.
                    last = k - 1
                    if (normal) then
                        call add_run(dtvs(k0), k0, k - 1, ctv, stv)
                        call add_run(kn, k0, k - 1, cnv, snv)
                    end if
                case default
                    any_event = .true.
                    last = k - 1
                end select
            end do
            call toeplitz_add(nh, n, ctu, stu, jac, 0_ip, 0_ip)
            if (normal) then
                call toeplitz_add(nh, n, ctv, stv, jac, 0_ip, nc)
                call toeplitz_add(nh, n, cnv, snv, jac, nc, nc)
            end if
            if (.not. any_event) then
                ! Stuck all cycle. If the slider moved while the march settled, every
                ! sample is anchored there: the whole-period sum of P is the mean row.
                a = plan%anchor(j)
                if (a == 0) return
                call anchor_rows(plan, j, a, plan%anchor_state(j), plan%anchor_dtv(j), kt, &
                                 normal, ru, rv)
                jac(1, 1:nc) = jac(1, 1:nc) - kt*ru
                if (normal) jac(1, nc + 1:2*nc) = jac(1, nc + 1:2*nc) - kt*rv
                return
            end if
            ! the segment through sample 1 (wrapping from the run that ends at N, if any)
            if (first_end > 0) call stick_segment(last, mod(last, n) + 1, first_end)
        end associate
    contains
        !> Starts of the runs of equal state (slip runs of the normal law also of equal
        !> d ft/dv, i.e. slip sign): starts(1:nrun), starts(nrun + 1) = N + 1. A tight
        !> loop without calls, so the scan keeps its operands in registers.
        pure subroutine run_starts(s, dtv, normal, starts, nrun)
            integer(ip), intent(in) :: s(:)       !! (N) states
            real(wp), intent(in) :: dtv(:)        !! (N) d ft/dv
            logical, intent(in) :: normal
            integer(ip), intent(out) :: starts(:) !! (N+1)
            integer(ip), intent(out) :: nrun
            integer(ip) :: k, slip_code
            logical :: new_run
            ! runs are maximal, so comparing with the previous sample is comparing with the
            ! run's first; slip_code: a state no sample has when the law has no slip sign
            slip_code = merge(STATE_SLIP, -1_ip, normal)
            nrun = 1
            starts(1) = 1
            do k = 2, size(s)
                new_run = s(k) /= s(k - 1) .or. (s(k) == slip_code .and. dtv(k) /= dtv(k - 1))
                if (.not. new_run) cycle
                nrun = nrun + 1
                starts(nrun) = k
            end do
            starts(nrun + 1) = size(s) + 1
        end subroutine run_starts

        !> jac -= kt g (ru, rv): stick samples i1..i2 (cyclic) anchored at sample a.
        subroutine stick_segment(a, i1, i2)
            integer(ip), intent(in) :: a, i1, i2
            integer(ip) :: c
            associate (g => plan%jw(:, 1), ru => plan%jw(:, 2), rv => plan%jw(:, 3))
                call segment_sum(plan%fp, i1, i2, g)
                call anchor_rows(plan, j, a, plan%state(j, a), plan%fp%rout(j, a, 4), kt, &
                                 normal, ru, rv)
                do c = 1, nc
                    jac(1:nc, c) = jac(1:nc, c) - kt*ru(c)*g
                end do
                if (normal) then
                    do c = 1, nc
                        jac(1:nc, nc + c) = jac(1:nc, nc + c) - kt*rv(c)*g
                    end do
                end if
            end associate
        end subroutine stick_segment

        !> C_m, S_m += value * sums of cos(m tau), sin(m tau) over samples k1..k2.
        pure subroutine add_run(value, k1, k2, cm, sm)
            real(wp), intent(in) :: value
            integer(ip), intent(in) :: k1, k2
            real(wp), intent(inout) :: cm(0:), sm(0:)
            integer(ip) :: m
            associate (pre => plan%fp%prefix)
                cm(0) = cm(0) + value*real(k2 - k1 + 1, wp)
                do m = 1, 2*nh
                    cm(m) = cm(m) + value*(pre(2*m, k2) - pre(2*m, k1 - 1))
                    sm(m) = sm(m) + value*(pre(2*m + 1, k2) - pre(2*m + 1, k1 - 1))
                end do
            end associate
        end subroutine add_run
    end subroutine jac_friction1d

    !> Derivative of the slider that anchors the stick samples after event sample a of
    !> element j of a 1-D law: dw = ru . dU + rv . dV (U, V: harmonics of u and v).
    !> Slip anchor: w = u_a - f_t(a)/kt with d f_t(a)/dv = dtv. Lift-off anchor (normal
    !> law; the next sample a+1 recloses): w = u_a + theta (u_{a+1} - u_a), theta =
    !> g_a/(g_a - g_{a+1}), g = n0 + kn v (frirom_contact), so theta moves with v_a, v_{a+1}.
    pure subroutine anchor_rows(plan, j, a, state, dtv, kt, normal, ru, rv)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: j, a, state
        real(wp), intent(in) :: dtv, kt
        logical, intent(in) :: normal           !! normal1d (else Jenkins: rv unused)
        real(wp), intent(out) :: ru(:), rv(:)   !! (nc)
        integer(ip) :: a1
        real(wp) :: g0, g1, theta, du
        associate (bas => plan%fp%basis, rin => plan%fp%rin, par => plan%par)
            ru = bas(a, :)
            if (.not. normal) then
                rv = 0.0_wp
                return
            end if
            if (state /= STATE_LIFTOFF) then
                rv = -(dtv/kt)*bas(a, :)
                return
            end if
            a1 = mod(a, plan%fp%nsamp) + 1
            g0 = par(j, 4) + par(j, 2)*rin(j, a, 2)
            g1 = par(j, 4) + par(j, 2)*rin(j, a1, 2)
            if (g1 <= 0.0_wp .or. g0 > 0.0_wp) then   ! no re-contact at a+1: w = u_a
                rv = 0.0_wp
                return
            end if
            theta = g0/(g0 - g1)
            du = rin(j, a1, 1) - rin(j, a, 1)
            ru = (1.0_wp - theta)*bas(a, :) + theta*bas(a1, :)
            rv = du*par(j, 2)*(g0*bas(a1, :) - g1*bas(a, :))/(g0 - g1)**2
        end associate
    end subroutine anchor_rows

    !> Jacobian of the 2-D element. The slip direction depends on the whole history, so
    !> the slider tangent dw (2 x 3(2H+1)) is propagated through the period from the
    !> closed cycle's own tangent, solved directly when that cycle is an isolated fixed
    !> point (fixed_point2d). Otherwise (stuck all cycle, or determined along a direction
    !> by less than DET_ISOLATED a period) the slider is history: the propagation starts
    !> from the tangent the settling periods leave (marched again from w0), so that the
    !> Jacobian is that of the forces as marched.
    subroutine jac_friction2d(plan, j, kt, w0j, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        real(wp), intent(in) :: w0j(:)        !! (2) the element's initial slider
        real(wp), intent(inout) :: jac(:, :)  !! (3 nc, 3 nc)
        integer(ip) :: nc
        nc = plan%fp%ncoef
        call jac_diagonal(plan, j, 4_ip, jac, 0_ip, 0_ip)       ! d f1/du1, stick
        call jac_diagonal(plan, j, 4_ip, jac, nc, nc)           ! d f2/du2, stick
        call jac_diagonal(plan, j, 5_ip, jac, 2*nc, 2*nc)       ! d fn/dv, contact
        ! a held history cycle (aft_forces' held) is differentiated as marched even where
        ! its last period would count as isolated
        if (plan%held(j) == 0) then
            if (fixed_point2d(plan, j, kt, jac)) return
        end if
        ! not isolated: the forces are those of the closed_at-th period marched plainly
        ! from w0 (frirom_aft_march), differentiated as such (the settling periods give
        ! the slider tangent at the start of the last one); a stepped cycle kept where the
        ! plain march does not close starts from its own slider, held
        plan%dw = 0.0_wp
        if (plan%closed_at(j) > 1 .and. .not. plan%accelerated(j)) &
            call settle2d(plan, j, kt, w0j, jac)
        if (all(plan%state(j, :) == STATE_STICK) .and. all(plan%dw == 0.0_wp)) return
        call propagate2d(plan, j, kt, .true., jac)
    end subroutine jac_friction2d

    !> Jacobian terms of a 2-D cycle that is an isolated fixed point of the period map
    !> (slider_fixed_point, the march's test): its slider, unique, does not depend on the
    !> settling periods, and its tangent solves dw = M dw + r exactly, r the tangent one
    !> period leaves from dw = 0 (the recursion repeated until it closes contracts as
    !> slowly as plain marching). .false. (nothing added) for a cycle that is not isolated.
    logical function fixed_point2d(plan, j, kt, jac) result(done)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        real(wp), intent(inout) :: jac(:, :)
        real(wp) :: a(2, 2), det
        real(wp) :: r1(size(plan%dw, 2)), r2(size(plan%dw, 2))
        logical :: opened
        call slider_fixed_point(plan, j, a, det, done, opened)
        if (.not. done) return
        plan%dw = 0.0_wp
        call propagate2d(plan, j, kt, .false., jac)
        r1 = plan%dw(1, :)
        r2 = plan%dw(2, :)
        call cramer2(a(1, 1), a(1, 2), a(2, 1), a(2, 2), det, r1, r2, plan%dw(1, :), &
                     plan%dw(2, :))
        call propagate2d(plan, j, kt, .true., jac)
    end function fixed_point2d

    !> Slider tangent dw that the settling periods of element j leave: march them again
    !> from w0j (dw = 0 there), propagating the tangent through each.
    subroutine settle2d(plan, j, kt, w0j, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt, w0j(:)
        real(wp), intent(inout) :: jac(:, :)
        integer(ip) :: n, per
        integer(ip), allocatable :: st(:, :), st_keep(:)
        real(wp), allocatable :: w(:, :), f(:, :, :), tg(:, :, :), tg_keep(:, :)
        n = plan%fp%nsamp
        allocate (st(1, n), w(1, 2), f(1, n, 3), tg(1, 12, n))
        st_keep = plan%state(j, :)
        tg_keep = plan%tangent(j, :, :)
        w(1, :) = w0j(1:2)
        plan%dw = 0.0_wp
        associate (rin => plan%fp%rin, par => plan%par, uf => plan%follow)
            do per = 1, plan%closed_at(j) - 1
                call friction2d_march(uf(j:j, :, 1), uf(j:j, :, 2), rin(j:j, :, 3), &
                                      par(j:j, 1), par(j:j, 2), par(j:j, 3), par(j:j, 4), w, &
                                      f(:, :, 1), f(:, :, 2), f(:, :, 3), st, tg)
                plan%state(j, :) = st(1, :)
                plan%tangent(j, :, :) = tg(1, :, :)
                call propagate2d(plan, j, kt, .false., jac)
            end do
        end associate
        plan%state(j, :) = st_keep
        plan%tangent(j, :, :) = tg_keep
    end subroutine settle2d

    !> One period of the 2-D slider tangent recursion (see friction2d_march):
    !> stick: d f = kt (dU_k - dw), dw kept; slip: d f = G_k (dU_{k-1} - dw) +
    !> A_k (dU_k - dU_{k-1}) + b_k dV_k + c_k dV_{k-1}, dw = dU_k - d f / kt; lift-off: d f = 0, dw = dU_k; a closed sample after an open
    !> one first puts the slider at the re-contact point (recontact). The same-sample
    !> stick part is in the Toeplitz blocks already; here only the terms in dw and the
    !> slip samples.
    subroutine propagate2d(plan, j, kt, accumulate, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        logical, intent(in) :: accumulate
        real(wp), intent(inout) :: jac(:, :)
        integer(ip) :: n, nc, k, i, c, kp
        real(wp) :: gsum(plan%fp%ncoef), pk(plan%fp%ncoef), rkt
        logical :: open_seg
        n = plan%fp%nsamp
        nc = plan%fp%ncoef
        rkt = -1.0_wp/kt                    ! (a divide per entry was a seventh of this)
        associate (st => plan%state(j, :), tg => plan%tangent(j, :, :), bas => plan%fp%basis, &
                   wgt => plan%fp%weight, dw => plan%dw, dft => plan%dft)
            gsum = 0.0_wp
            open_seg = .false.
            do k = 1, n
                kp = k - 1
                if (k == 1) kp = n
                if (st(k) /= STATE_LIFTOFF .and. st(kp) == STATE_LIFTOFF) call recontact(kp, k)
                if (st(k) == STATE_STICK) then
                    if (accumulate) gsum = gsum + wgt*bas(k, :)
                    open_seg = .true.
                    cycle
                end if
                if (open_seg .and. accumulate) call flush_stick(gsum)
                open_seg = .false.
                if (st(k) == STATE_SLIP) then
                    ! G (du_{k-1} - dw) + A (du_k - du_{k-1}) + b dv_k + c dv_{k-1}
                    ! (friction2d_march); after an open sample A = G and c = 0
                    dft(1, :) = -(tg(1, k)*dw(1, :) + tg(3, k)*dw(2, :))
                    dft(2, :) = -(tg(2, k)*dw(1, :) + tg(4, k)*dw(2, :))
                    do i = 1, 2
                        do c = 1, 2
                            dft(i, (c - 1)*nc + 1:c*nc) = dft(i, (c - 1)*nc + 1:c*nc) &
                                + tg(6 + i + 2*(c - 1), k)*bas(k, :) &
                                + (tg(i + 2*(c - 1), k) - tg(6 + i + 2*(c - 1), k))*bas(kp, :)
                        end do
                        dft(i, 2*nc + 1:3*nc) = dft(i, 2*nc + 1:3*nc) + tg(4 + i, k)*bas(k, :) &
                                                + tg(10 + i, k)*bas(kp, :)
                    end do
                    if (accumulate) then
                        pk = wgt*bas(k, :)
                        do i = 1, 2
                            do c = 1, 3*nc
                                jac((i - 1)*nc + 1:i*nc, c) = jac((i - 1)*nc + 1:i*nc, c) &
                                                              + pk*dft(i, c)
                            end do
                        end do
                    end if
                    dw = dft*rkt
                else
                    dw = 0.0_wp
                end if
                dw(1, 1:nc) = dw(1, 1:nc) + bas(k, :)
                dw(2, nc + 1:2*nc) = dw(2, nc + 1:2*nc) + bas(k, :)
            end do
            if (open_seg .and. accumulate) call flush_stick(gsum)
        end associate
    contains
        !> Stick samples since the last event: d f_i = -kt dw_i, summed by analysis weights.
        subroutine flush_stick(g)
            real(wp), intent(inout) :: g(:)
            integer(ip) :: ii, cc
            do ii = 1, 2
                do cc = 1, 3*nc
                    jac((ii - 1)*nc + 1:ii*nc, cc) = jac((ii - 1)*nc + 1:ii*nc, cc) &
                                                     - kt*g*plan%dw(ii, cc)
                end do
            end do
            g = 0.0_wp
        end subroutine flush_stick

        !> Slider tangent at the re-contact point between open sample kp and closed sample
        !> k: w = u_kp + theta (u_k - u_kp), theta = g_kp/(g_kp - g_k), g = n0 + kn v.
        subroutine recontact(kp, k)
            integer(ip), intent(in) :: kp, k
            real(wp) :: g0, g1, theta, dth(plan%fp%ncoef)
            integer(ip) :: ii
            associate (rin => plan%fp%rin, par => plan%par, bas => plan%fp%basis)
                g0 = par(j, 4) + par(j, 2)*rin(j, kp, 3)
                g1 = par(j, 4) + par(j, 2)*rin(j, k, 3)
                theta = g0/(g0 - g1)
                dth = par(j, 2)*(g0*bas(k, :) - g1*bas(kp, :))/(g0 - g1)**2
                plan%dw = 0.0_wp
                do ii = 1, 2
                    plan%dw(ii, (ii - 1)*nc + 1:ii*nc) = (1.0_wp - theta)*bas(kp, :) &
                                                         + theta*bas(k, :)
                    plan%dw(ii, 2*nc + 1:3*nc) = (rin(j, k, ii) - rin(j, kp, ii))*dth
                end do
            end associate
        end subroutine recontact
    end subroutine propagate2d
end submodule frirom_aft_jacobian
