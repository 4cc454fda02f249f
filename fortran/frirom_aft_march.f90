!> AFT time samples: displacement harmonics of a batch of elements to time samples, then
!> the contact law marched period after period until every slider closes its cycle.
!> The hot path of frirom: the march and its per-period bookkeeping stay in this one
!> submodule so that the compiler sees them together.
submodule (frirom_aft) frirom_aft_march
    use frirom_fourier, only: clear_input, load_harmonics, exec_c2r, synth_direct
    use frirom_contact, only: STATE_STICK, STATE_SLIP, STATE_LIFTOFF, jenkins_march, &
                              friction1d_march, friction2d_march, cubic_spring, &
                              recontact_follow
    implicit none

contains

    module procedure time_batch
        integer(ip) :: d, j
        do d = 1, NDIR_OF(law)
            if (plan%fp%direct) then
                do j = 1, m
                    plan%fp%coef(j, :) = x(:, d, e0 + j - 1)
                end do
                call synth_direct(plan%fp, d, m)
                cycle
            end if
            call clear_input(plan%fp, d)
            do j = 1, m
                call load_harmonics(plan%fp, d, j, x(:, d, e0 + j - 1))
            end do
            call exec_c2r(plan%fp, d)
        end do
        call march_closed(plan, law, m, params(:, e0:e0 + m - 1), w0(:, e0:e0 + m - 1), tol, &
                          max_periods)
    end procedure time_batch

    !> March the first m elements of the batch period after period until every slider
    !> closes its cycle; the last period's forces (output slots 1..ndir), states and
    !> tangents stay in the plan. closed_at(j) = period element j closed in, or
    !> max_periods + 1. 2-D elements that closed earlier keep their closed period (the
    !> others march on alone: march_open2d); 1-D ones repeat their closed cycle exactly.
    subroutine march_closed(plan, law, m, p, w0, tol, max_periods)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, m
        real(wp), intent(in) :: p(:, :)    !! (npar, m)
        real(wp), intent(in) :: w0(:, :)   !! (nslider, m)
        real(wp), intent(in) :: tol
        integer(ip), intent(in) :: max_periods
        integer(ip) :: ns, d, j, i, nper
        real(wp) :: a(2, 2), det, res
        logical :: isolated, opened
        associate (rin => plan%fp%rin, rout => plan%fp%rout, st => plan%state(1:m, :), &
                   w => plan%w(1:m, :), par => plan%par(1:m, :), uf => plan%follow(1:m, :, :))
            ns = NSLIDER_OF(law)
            do i = 1, NPAR_OF(law)
                par(:, i) = p(i, :)
            end do
            plan%anchor(1:m) = 0
            if (law == LAW_CUBIC) then
                call cubic_spring(rin(1:m, :, 1), spread(par(:, 1), 2, plan%fp%nsamp), &
                                  spread(par(:, 2), 2, plan%fp%nsamp), rout(1:m, :, 1), &
                                  rout(1:m, :, 2))
                st = STATE_STICK
                plan%closed_at(1:m) = 1
                return
            end if
            w = 0.0_wp
            do i = 1, ns
                w(:, i) = w0(i, :)
            end do
            do j = 1, m
                plan%scale(j) = max(tiny(1.0_wp), maxval(abs(w(j, 1:ns))))
            end do
            do d = 1, NDIR_OF(law)      ! sample by sample over the batch (contiguous)
                do i = 1, plan%fp%nsamp
                    plan%scale(1:m) = max(plan%scale(1:m), abs(rin(1:m, i, d)))
                end do
            end do
            ! where the sliders follow the contact point while it is open: fixed in u and v,
            ! so once for all periods
            if (law /= LAW_JENKINS) then
                do d = 1, ns
                    call recontact_follow(rin(1:m, :, d), rin(1:m, :, NDIR_OF(law)), par(:, 2), &
                                          par(:, 4), uf(:, :, d))
                end do
            end if
            if (law == LAW_NORMAL1D .and. m < plan%fp%nbatch) then
                ! a short last batch: its unused lanes march an element at rest, so that the
                ! march runs over the whole (contiguous) batch arrays
                plan%par(m + 1:, :) = 0.0_wp
                plan%par(m + 1:, 1) = 1.0_wp
                plan%follow(m + 1:, :, 1) = 0.0_wp
                rin(m + 1:, :, 2) = 0.0_wp
                plan%w(m + 1:, 1) = 0.0_wp
            end if
            plan%closed_at(1:m) = max_periods + 1
            plan%stepped(1:m) = .false.
            plan%drifting(1:m) = .false.
            plan%unsettled(1:m) = .false.
            plan%accelerated(1:m) = .false.
            plan%hold(1:m) = 0
            plan%damp(1:m) = 1.0_wp
            plan%damp_cap(1:m) = 1.0_wp
            do nper = 1, max_periods
                if (law /= LAW_NORMAL2D) plan%wstart(1:m, :) = w
                select case (law)
                case (LAW_JENKINS)
                    call jenkins_march(rin(1:m, :, 1), par(:, 1), par(:, 2), par(:, 3), w(:, 1), &
                                       rout(1:m, :, 1), st)
                case (LAW_NORMAL1D)
                    ! the whole batch, contiguous (lanes m+1.. hold the inert tail set above)
                    call friction1d_march(plan%follow(:, :, 1), rin(:, :, 2), plan%par(:, 1), &
                                          plan%par(:, 2), plan%par(:, 3), plan%par(:, 4), &
                                          plan%w(:, 1), rout(:, :, 1), rout(:, :, 2), &
                                          plan%state, rout(:, :, 4))
                case (LAW_NORMAL2D)
                    ! only the cycles still open march on: one closed keeps its period as
                    ! it closed (marched on, a history slider would drift on)
                    call march_open2d(plan, m, max_periods)
                end select
                call record_anchors(plan, law, m)
                do j = 1, m
                    if (plan%closed_at(j) > max_periods) then
                        if (law == LAW_NORMAL2D) then
                            if (plan%held(j) > 0) then      ! a held history cycle
                                if (nper >= plan%held(j)) then
                                    plan%closed_at(j) = nper
                                    res = maxval(abs(w(j, 1:2) - plan%wstart(j, 1:2)))
                                    plan%unsettled(j) = plan%held(j) < max_periods .and. &
                                        res > max(tol, UNSETTLED)*plan%scale(j)
                                    ! still drifting at max_periods: as unheld (below)
                                    plan%drifting(j) = plan%held(j) >= max_periods .and. &
                                        res > max(tol, DRIFT)*plan%scale(j)
                                end if
                            else
                                call settle_step2d(plan, j, nper, tol*plan%scale(j))
                            end if
                        else if (maxval(abs(w(j, 1:ns) - plan%wstart(j, 1:ns))) <= &
                                 tol*plan%scale(j)) then
                            plan%closed_at(j) = nper
                        end if
                    end if
                end do
                if (all(plan%closed_at(1:m) <= max_periods)) exit
            end do
            if (law == LAW_NORMAL2D) then
                ! (a cycle closed before the batch's last period kept the period it closed
                ! in: march_open2d; marched on, a history slider would drift on and its
                ! forces depend on how long the other elements of its batch take)
                do j = 1, m
                    ! a history slider still drifting by more than DRIFT after max_periods
                    ! plain periods is the state they leave (a fixed count: smooth in the
                    ! motion), as a stuck one is; a paper-hooks ROM_II sweep (300 N down)
                    ! stopped on one at 137.29 Hz
                    if (plan%closed_at(j) <= max_periods .or. plan%accelerated(j)) cycle
                    call slider_fixed_point(plan, j, a, det, isolated, opened)
                    if (isolated .or. opened) cycle
                    plan%closed_at(j) = max_periods
                    plan%drifting(j) = .true.
                end do
                do j = 1, m
                    if (.not. plan%accelerated(j)) cycle
                    call slider_fixed_point(plan, j, a, det, isolated, opened)
                    if (.not. isolated) call march_plain2d(plan, j, w0(:, j), tol, max_periods)
                end do
                do j = 1, m         ! a history cycle: its period count, to be held (HELD)
                    if (plan%held(j) > 0 .or. plan%accelerated(j) .or. &
                        plan%closed_at(j) > max_periods) cycle
                    call slider_fixed_point(plan, j, a, det, isolated, opened)
                    if (.not. isolated) plan%held(j) = plan%closed_at(j)
                end do
            end if
        end associate
    end subroutine march_closed

    !> One period of the 2-D law for the elements of the batch's first m whose cycle is
    !> still open (closed_at > max_periods), run by run of consecutive open elements: a
    !> closed element keeps the period it closed in (forces, states, tangents, its slider
    !> at the start and end), and a batch whose last open element drifts to max_periods
    !> (a history cycle, held or not) marches that one alone.
    subroutine march_open2d(plan, m, max_periods)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: m, max_periods
        integer(ip) :: j1, j2
        associate (rin => plan%fp%rin, rout => plan%fp%rout, par => plan%par, &
                   uf => plan%follow)
            j1 = 1
            do while (j1 <= m)
                if (plan%closed_at(j1) <= max_periods) then
                    j1 = j1 + 1
                    cycle
                end if
                j2 = j1
                do while (j2 < m)
                    if (plan%closed_at(j2 + 1) <= max_periods) exit
                    j2 = j2 + 1
                end do
                plan%wstart(j1:j2, :) = plan%w(j1:j2, :)
                call friction2d_march(uf(j1:j2, :, 1), uf(j1:j2, :, 2), rin(j1:j2, :, 3), &
                                      par(j1:j2, 1), par(j1:j2, 2), par(j1:j2, 3), &
                                      par(j1:j2, 4), plan%w(j1:j2, :), rout(j1:j2, :, 1), &
                                      rout(j1:j2, :, 2), rout(j1:j2, :, 3), &
                                      plan%state(j1:j2, :), plan%tangent(j1:j2, :, :))
                j1 = j2 + 1
            end do
        end associate
    end subroutine march_open2d

    !> Closure test and slider update of 2-D element j after period nper: plain marching
    !> accelerated by Newton steps on the slider fixed point w = P(w) (P: one period).
    !>
    !> Each slip sample corrects the slider only along its slip direction, so P contracts
    !> the mismatch orthogonal to it by little more than the ratio of friction limit to
    !> trial force: about 0.99 a period at the onset of partial slip. Its derivative
    !> M = dP/dw (slider_map) is known from the period just marched, so when plain marching
    !> is slow (the mismatch shrank less than SLOW times in the last period) or the last
    !> step was good, the next period starts from w_s + (I - M)^-1 (P(w_s) - w_s) instead of
    !> P(w_s). The step is kept if the period marched from it still slips and has a smaller
    !> mismatch than its base; otherwise the slider goes back to P(w_s), where plain
    !> marching would be, HOLD plain periods follow, and the fraction of the step taken
    !> halves and stays at most that for the rest of the march (damp_cap: near a cycle
    !> that only touches the limit, doubling it again after each kept step was rejected
    !> every other time; a recorded hook element closed in 73 periods instead of 250). A
    !> cycle is closed only by a plain or kept period. A cycle that sticks, or whose
    !> slider one period determines along some direction by less than DET_ISOLATED (it
    !> barely slips to and fro along one line) is one of a set or nearly so: its slider is
    !> history, like a stuck 1-D slider's, so it is marched plainly from w0 and closes once
    !> it drifts by less than DRIFT a period (a step ~1/det long would make the forces
    !> hypersensitive: a hook element of the paper mesh, det 2.3e-6, took 175 periods of
    !> steps and did not close after a change of 1e-5 in its motion). Only one that drifts
    !> faster still takes steps; if it ends not isolated it is marched again without them
    !> (march_plain2d).
    subroutine settle_step2d(plan, j, nper, tolj)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j, nper
        real(wp), intent(in) :: tolj         !! closure tolerance of the element, m
        !> plain contraction per period below which no step is tried
        real(wp), parameter :: SLOW = 0.1_wp
        !> smallest det(I - M) a step is taken with
        real(wp), parameter :: DET_MIN = 1.0e-8_wp
        integer(ip), parameter :: HOLD = 2
        real(wp), parameter :: DAMP_MIN = 2.0_wp**(-12)
        real(wp) :: res, a(2, 2), det, g(2), x(2)
        logical :: opened, isolated, try
        associate (w => plan%w(j, 1:2), ws => plan%wstart(j, 1:2))
            res = maxval(abs(w - ws))
            try = .false.
            if (plan%stepped(j)) then
                plan%stepped(j) = .false.
                if (all(plan%state(j, :) == STATE_STICK) .or. res >= plan%res_base(j)) then
                    w = plan%wplain(j, :)
                    plan%res_last(j) = plan%res_base(j)
                    plan%hold(j) = HOLD
                    plan%damp(j) = max(0.5_wp*plan%damp(j), DAMP_MIN)
                    plan%damp_cap(j) = plan%damp(j)
                    return
                end if
                plan%damp(j) = min(2.0_wp*plan%damp(j), plan%damp_cap(j))
                try = .true.
            end if
            if (res <= tolj) then
                plan%closed_at(j) = nper
                return
            end if
            call slider_fixed_point(plan, j, a, det, isolated, opened)
            if (.not. isolated) then
                ! the slider is history along its weak direction: closed once it drifts by
                ! less than DRIFT a period; a step towards a fixed point ~1/det away only
                ! as a last resort, where the drift stays above that (see above)
                if (res <= max(tolj, DRIFT*plan%scale(j))) then
                    plan%closed_at(j) = nper
                    return
                end if
                if (abs(det) < DET_MIN) then
                    plan%res_last(j) = res
                    return
                end if
            end if
            if (nper > 1) try = try .or. res > SLOW*plan%res_last(j)
            try = try .and. plan%hold(j) == 0
            plan%hold(j) = max(plan%hold(j) - 1, 0_ip)
            plan%res_last(j) = res
            if (.not. try) return
            if (opened) return
            g = w - ws
            plan%wplain(j, :) = w
            plan%res_base(j) = res
            call cramer2(a(1, 1), a(1, 2), a(2, 1), a(2, 2), det, g(1), g(2), x(1), x(2))
            w = ws + plan%damp(j)*x        ! damp: a power of 2
            plan%stepped(j) = .true.
            plan%accelerated(j) = .true.
        end associate
    end subroutine settle_step2d

    module procedure slider_fixed_point
        real(wp) :: mm(2, 2)
        call slider_map(plan, j, plan%par(j, 1), mm, opened)
        a(1, 1) = 1.0_wp - mm(1, 1)
        a(2, 1) = -mm(2, 1)
        a(1, 2) = -mm(1, 2)
        a(2, 2) = 1.0_wp - mm(2, 2)
        det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
        isolated = det >= DET_ISOLATED
    end procedure slider_fixed_point

    module procedure cramer2
        x1 = (a22*g1 - a12*g2)/det
        x2 = (a11*g2 - a21*g1)/det
    end procedure cramer2

    !> Derivative m(2, 2) of the end-of-period 2-D slider of element j of the batch with
    !> respect to its start, from the states and slip tangents of the period just
    !> marched: the product over the samples of G_k/kt at slip, I at stick, 0 at
    !> lift-off. opened: the period has a lift-off sample.
    pure subroutine slider_map(plan, j, kt, m, opened)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        real(wp), intent(out) :: m(2, 2)
        logical, intent(out) :: opened
        integer(ip) :: k
        real(wp) :: b(2, 2)
        m = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
        opened = .false.
        do k = 1, plan%fp%nsamp
            select case (plan%state(j, k))
            case (STATE_SLIP)
                b(1, 1) = plan%tangent(j, 1, k)/kt
                b(2, 1) = plan%tangent(j, 2, k)/kt
                b(1, 2) = plan%tangent(j, 3, k)/kt
                b(2, 2) = plan%tangent(j, 4, k)/kt
                m = matmul(b, m)
            case (STATE_LIFTOFF)
                m = 0.0_wp
                opened = .true.
            end select
        end do
    end subroutine slider_map

    !> March 2-D element j again from w0j without steps, for a march with a kept step whose
    !> closed cycle is not isolated (slider_fixed_point): its slider is history, so the
    !> plain march replaces the stepped cycle, closed on its drift or after max_periods
    !> periods (the state settle2d of frirom_aft_jacobian differentiates).
    subroutine march_plain2d(plan, j, w0j, tol, max_periods)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j, max_periods
        real(wp), intent(in) :: w0j(:)    !! (2) initial slider, m
        real(wp), intent(in) :: tol
        integer(ip) :: nper
        real(wp) :: res, lim, a(2, 2), det
        logical :: isolated, opened
        associate (rin => plan%fp%rin, rout => plan%fp%rout, par => plan%par, &
                   uf => plan%follow)
            plan%w(j, 1:2) = w0j(1:2)
            do nper = 1, max_periods
                plan%wstart(j, 1:2) = plan%w(j, 1:2)
                call friction2d_march(uf(j:j, :, 1), uf(j:j, :, 2), rin(j:j, :, 3), &
                                      par(j:j, 1), par(j:j, 2), par(j:j, 3), par(j:j, 4), &
                                      plan%w(j:j, 1:2), rout(j:j, :, 1), rout(j:j, :, 2), &
                                      rout(j:j, :, 3), plan%state(j:j, :), &
                                      plan%tangent(j:j, :, :))
                res = maxval(abs(plan%w(j, 1:2) - plan%wstart(j, 1:2)))
                call slider_fixed_point(plan, j, a, det, isolated, opened)
                lim = tol*plan%scale(j)
                if (.not. isolated) lim = max(lim, DRIFT*plan%scale(j))   ! as settle_step2d
                if (res <= lim) then
                    plan%closed_at(j) = nper
                    plan%accelerated(j) = .false.
                    return
                end if
            end do
        end associate
        ! plain marching does not close on its drift either: the state its max_periods
        ! periods leave, as march_closed keeps for an unstepped history slider. (The stepped
        ! cycle's slider, ~1/det from w0, moves by ~1/det times any change of the motion:
        ! kept, with a Jacobian that held it, a corrector of the coarse hooks' ROM_I stalled
        ! at 181.3 Hz, |R|/rref 2e-8; kept as a fixed point, with its Jacobian, the sweep
        ! crawled there in 1 300 points and stopped on a cycle that would not close.)
        plan%closed_at(j) = max_periods
        plan%accelerated(j) = .false.
        plan%drifting(j) = .true.
    end subroutine march_plain2d

    !> Remember the last slip or lift-off sample of the period just marched: a contact that
    !> slips while the march settles and then sticks for good keeps its slider where that
    !> sample left it, so the mean force still depends on the displacement there.
    pure subroutine record_anchors(plan, law, m)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, m
        integer(ip) :: j, k
        do j = 1, m
            do k = plan%fp%nsamp, 1, -1
                if (plan%state(j, k) /= STATE_STICK) then
                    plan%anchor(j) = k
                    plan%anchor_state(j) = plan%state(j, k)
                    plan%anchor_dtv(j) = 0.0_wp
                    if (law == LAW_NORMAL1D) plan%anchor_dtv(j) = plan%fp%rout(j, k, 4)
                    exit
                end if
            end do
        end do
    end subroutine record_anchors
end submodule frirom_aft_march
