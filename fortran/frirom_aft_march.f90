!> AFT time samples: displacement harmonics of a batch of elements to time samples, then
!> the contact law marched period after period until every slider closes its cycle.
!> The hot path of frirom: the march and its per-period bookkeeping stay in this one
!> submodule so that the compiler sees them together.
submodule (frirom_aft) frirom_aft_march
    use frirom_fourier, only: clear_input, load_harmonics, exec_c2r
    use frirom_contact, only: STATE_STICK, jenkins_march, friction1d_march, friction2d_march, &
                              cubic_spring, recontact_follow
    implicit none

contains

    module procedure time_batch
        integer(ip) :: d, j
        do d = 1, NDIR_OF(law)
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
    !> max_periods + 1. Elements that closed earlier repeat their closed cycle exactly.
    subroutine march_closed(plan, law, m, p, w0, tol, max_periods)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, m
        real(wp), intent(in) :: p(:, :)    !! (npar, m)
        real(wp), intent(in) :: w0(:, :)   !! (nslider, m)
        real(wp), intent(in) :: tol
        integer(ip), intent(in) :: max_periods
        integer(ip) :: ns, d, j, i, nper
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
                do d = 1, NDIR_OF(law)
                    plan%scale(j) = max(plan%scale(j), maxval(abs(rin(j, :, d))))
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
            plan%closed_at(1:m) = max_periods + 1
            do nper = 1, max_periods
                plan%wstart(1:m, :) = w
                select case (law)
                case (LAW_JENKINS)
                    call jenkins_march(rin(1:m, :, 1), par(:, 1), par(:, 2), par(:, 3), w(:, 1), &
                                       rout(1:m, :, 1), st)
                case (LAW_NORMAL1D)
                    call friction1d_march(uf(:, :, 1), rin(1:m, :, 2), par(:, 1), par(:, 2), &
                                          par(:, 3), par(:, 4), w(:, 1), rout(1:m, :, 1), &
                                          rout(1:m, :, 2), st, rout(1:m, :, 4))
                case (LAW_NORMAL2D)
                    call friction2d_march(uf(:, :, 1), uf(:, :, 2), rin(1:m, :, 3), &
                                          par(:, 1), par(:, 2), par(:, 3), par(:, 4), w, &
                                          rout(1:m, :, 1), rout(1:m, :, 2), rout(1:m, :, 3), &
                                          st, plan%tangent(1:m, :, :))
                end select
                call record_anchors(plan, law, m)
                do j = 1, m
                    if (plan%closed_at(j) > max_periods) then
                        if (maxval(abs(w(j, 1:ns) - plan%wstart(j, 1:ns))) <= tol*plan%scale(j)) &
                            plan%closed_at(j) = nper
                    end if
                end do
                if (all(plan%closed_at(1:m) <= max_periods)) return
            end do
        end associate
    end subroutine march_closed

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
