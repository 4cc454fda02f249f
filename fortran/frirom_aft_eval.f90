!> AFT entry points: forces and Jacobian (aft_eval), time histories (aft_time), and the
!> checks of their arguments before any work. See frirom_aft for the method.
submodule (frirom_aft) frirom_aft_eval
    use frirom_status, only: FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_NONFINITE, FRIROM_ERR_NOCLOSE, set_status, &
                             frirom_status_message
    use frirom_fourier, only: exec_r2c, harmonics_of, analyse_direct
    use frirom_contact, only: STATE_STICK, STATE_SLIP, STATE_LIFTOFF
    implicit none

contains

    module procedure aft_forces
        integer(ip) :: ne, nd, nc, nb, e0, m, j, e, s, np, nper, nfail, base, mp
        real(wp) :: tl
        logical :: want_jac, rel
        character(len=200) :: buf

        call check_call(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                        index_base, slider)
        if (info /= FRIROM_OK) return
        call defaults(tol, max_periods, index_base, tl, mp, base)
        if (present(settled)) settled = .true.
        if (present(held)) then
            if (size(held) /= size(x, 3)) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'held must be (ne)')
                return
            end if
        end if
        if (law == LAW_IWAN4 .or. law == LAW_IWAN) then
            call iwan_forces(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                             tl, mp, base, slider)
            return
        end if
        want_jac = present(jac)
        rel = .false.
        if (present(relative)) rel = relative .and. (law == LAW_NORMAL1D .or. &
                                                     law == LAW_NORMAL2D)
        nd = NDIR_OF(law)
        ne = size(x, 3)
        nc = plan%fp%ncoef
        nb = plan%fp%nbatch
        np = nd
        nfail = 0
        if (want_jac) jac = 0.0_wp

        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
            plan%held(1:m) = 0
            if (present(held) .and. law == LAW_NORMAL2D) plan%held(1:m) = held(e0:e0 + m - 1)
            call time_batch(plan, law, x, params, w0, e0, m, tl, mp)
            if (present(held) .and. law == LAW_NORMAL2D) held(e0:e0 + m - 1) = plan%held(1:m)
            if (present(settled) .and. law == LAW_NORMAL2D) &
                settled = settled .and. .not. any(plan%unsettled(1:m))
            do j = 1, m
                e = e0 + j - 1
                nper = plan%closed_at(j)
                if (nper > mp .and. nfail == 0) then
                    nfail = e
                    write (buf, '(a,i0,a,i0,a)') 'element ', e - 1 + base, ': not closed after ', &
                        mp, ' periods'
                end if
                if (present(periods)) periods(e) = min(nper, mp)
                if (present(slider) .and. NSLIDER_OF(law) > 0) &
                    slider(1:NSLIDER_OF(law), e) = plan%w(j, 1:NSLIDER_OF(law))
                if (present(slider) .and. law == LAW_NORMAL2D) then
                    if (plan%drifting(j)) slider(1:2, e) = w0(1:2, e)
                end if
            end do
            if (present(states)) call state_fractions(plan%state, m, states(:, e0:e0 + m - 1))
            ! the series slots are read by the 2-D law's Jacobian only (the 1-D one scans the
            ! states, the cubic reads its march's derivative)
            if (want_jac .and. law == LAW_NORMAL2D) call fill_series(plan, m)
            if (rel) call relative_normal(m)
            do s = 1, np
                if (plan%fp%direct) then
                    call analyse_direct(plan%fp, s, m)
                    do j = 1, m
                        f(:, s, e0 + j - 1) = plan%fp%coef(j, :)
                    end do
                else
                    call exec_r2c(plan%fp, s)
                    do j = 1, m
                        call harmonics_of(plan%fp, s, j, f(:, s, e0 + j - 1))
                    end do
                end if
            end do
            do j = 1, m
                e = e0 + j - 1
                if (want_jac) call element_jacobian(plan, law, j, params(:, e), w0(:, e), &
                                                    jac(:, :, e))
            end do
        end do
        if (nfail /= 0) call set_status(info, FRIROM_ERR_NOCLOSE, errmsg, trim(buf))

    contains

        !> The normal force samples of the batch's mb elements less their force at rest
        !> max(n0, 0): kn v where closed, -n0 open (the march's max(n0 + kn v, 0) - n0,
        !> without the rounding of n0 + kn v).
        subroutine relative_normal(mb)
            integer(ip), intent(in) :: mb
            integer(ip) :: jj
            associate (rin => plan%fp%rin, rout => plan%fp%rout, par => plan%par)
                do jj = 1, mb
                    if (par(jj, 4) <= 0.0_wp) cycle
                    rout(jj, :, nd) = merge(-par(jj, 4), par(jj, 2)*rin(jj, :, nd), &
                                            plan%state(jj, :) == STATE_LIFTOFF)
                end do
            end associate
        end subroutine relative_normal
    end procedure aft_forces

    module procedure aft_histories
        real(wp), allocatable :: fh(:, :, :)
        integer(ip) :: ne, nd, nb, e0, m, j, e, d, mp, base
        real(wp) :: tl

        allocate (fh(size(x, 1), size(x, 2), size(x, 3)))
        call check_call(plan, law, x, params, w0, fh, info, errmsg, index_base=index_base)
        if (info /= FRIROM_OK) return
        if (size(xt, 1) /= plan%fp%nsamp .or. size(ft, 1) /= plan%fp%nsamp .or. &
            any(shape(xt) /= shape(ft)) .or. size(xt, 2) /= size(x, 2) .or. &
            size(xt, 3) /= size(x, 3)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'xt and ft must be (N, ndir, ne)')
            return
        end if
        call defaults(tol, max_periods, index_base, tl, mp, base)
        if (law == LAW_IWAN4 .or. law == LAW_IWAN) then
            call iwan_histories(plan, law, x, params, w0, xt, ft, info, errmsg, tl, mp, base)
            return
        end if
        nd = NDIR_OF(law)
        ne = size(x, 3)
        nb = plan%fp%nbatch
        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
            plan%held(1:m) = 0
            call time_batch(plan, law, x, params, w0, e0, m, tl, mp)
            do j = 1, m
                e = e0 + j - 1
                if (plan%closed_at(j) > mp .and. info == FRIROM_OK) then
                    info = FRIROM_ERR_NOCLOSE
                    if (present(errmsg)) write (errmsg, '(a,a,i0)') &
                        frirom_status_message(info), ': element ', e - 1 + base
                end if
                do d = 1, nd
                    xt(:, d, e) = plan%fp%rin(j, :, d)
                    ft(:, d, e) = plan%fp%rout(j, :, d)
                end do
            end do
        end do
    end procedure aft_histories

    !> The optional settings of an AFT call, or their defaults.
    pure subroutine defaults(tol, max_periods, index_base, tl, mp, base)
        real(wp), intent(in), optional :: tol
        integer(ip), intent(in), optional :: max_periods, index_base
        real(wp), intent(out) :: tl
        integer(ip), intent(out) :: mp, base
        tl = DEFAULT_TOL
        if (present(tol)) tl = tol
        mp = DEFAULT_MAX_PERIODS
        if (present(max_periods)) mp = max_periods
        base = 1
        if (present(index_base)) base = index_base
    end subroutine defaults

    !> Shapes, law and parameters of an AFT call, checked before any work.
    subroutine check_call(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                          index_base, slider)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :), f(:, :, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        real(wp), intent(in), optional :: jac(:, :, :)
        integer(ip), intent(in), optional :: periods(:)
        real(wp), intent(in), optional :: states(:, :)
        integer(ip), intent(in), optional :: index_base
        real(wp), intent(in), optional :: slider(:, :)
        integer(ip) :: ne, nc, nd, e, base
        character(len=200) :: buf, why

        info = FRIROM_OK
        base = 1
        if (present(index_base)) base = index_base
        if (plan%fp%nsamp <= 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'AFT plan not created')
            return
        end if
        call law_check(law, info, errmsg)
        if (info /= FRIROM_OK) return
        nc = plan%fp%ncoef
        nd = NDIR_OF(law)
        ne = size(x, 3)
        if (size(x, 1) /= nc .or. size(x, 2) /= nd) then
            write (buf, '(a,i0,a,i0,a,i0,a,i0,a)') 'x is (', size(x, 1), ', ', size(x, 2), &
                ', ne); expected (2H+1 = ', nc, ', ndir = ', nd, ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        else if (any(shape(f) /= shape(x))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'f must have the shape of x')
        else if (size(params, 1) /= NPAR_OF(law) .or. size(params, 2) /= ne) then
            write (buf, '(a,i0,a,i0,a,i0,a)') 'params is (', size(params, 1), ', ', &
                size(params, 2), '); expected (', NPAR_OF(law), ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        else if (size(w0, 1) < NSLIDER_OF(law) .or. &
                 (NSLIDER_OF(law) > 0 .and. size(w0, 2) /= ne)) then
            write (buf, '(a,i0,a)') 'w0 must be (', NSLIDER_OF(law), ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        end if
        if (info /= FRIROM_OK) return
        if (present(jac)) then
            if (size(jac, 1) /= nc*nd .or. size(jac, 2) /= nc*nd .or. size(jac, 3) /= ne) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, &
                                'jac must be (ndir(2H+1), ndir(2H+1), ne)')
                return
            end if
        end if
        if (present(periods)) then
            if (size(periods) /= ne) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'periods must be (ne)')
                return
            end if
        end if
        if (present(states)) then
            if (size(states, 1) /= 3 .or. size(states, 2) /= ne) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'states must be (3, ne)')
                return
            end if
        end if
        if (present(slider)) then
            if (size(slider, 1) < NSLIDER_OF(law) .or. size(slider, 2) /= ne) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'slider must be (nslider, ne)')
                return
            end if
        end if
        do e = 1, ne
            if (.not. all(abs(x(:, :, e)) <= huge(1.0_wp))) then
                write (buf, '(a,i0,a)') 'displacement harmonics of element ', e - 1 + base, &
                    ' are not finite'
                call set_status(info, FRIROM_ERR_NONFINITE, errmsg, trim(buf))
                return
            end if
            if (NSLIDER_OF(law) > 0) then
                if (.not. all(abs(w0(1:NSLIDER_OF(law), e)) <= huge(1.0_wp))) then
                    write (buf, '(a,i0,a)') 'initial slider of element ', e - 1 + base, &
                        ' is not finite'
                    call set_status(info, FRIROM_ERR_NONFINITE, errmsg, trim(buf))
                    return
                end if
            end if
            call check_params(law, params(:, e), why)
            if (len_trim(why) > 0) then
                write (buf, '(a,i0,a,a)') 'element ', e - 1 + base, ': ', trim(why)
                call set_status(info, FRIROM_ERR_PARAM, errmsg, trim(buf))
                return
            end if
        end do
    end subroutine check_call

    !> Empty `why` when the parameters of one element are admissible for its law.
    pure subroutine check_params(law, p, why)
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: p(:)
        character(len=*), intent(out) :: why
        why = ''
        if (.not. all(abs(p) <= huge(1.0_wp))) then
            why = 'parameters are not finite'
            return
        end if
        select case (law)
        case (LAW_JENKINS)
            if (p(1) <= 0.0_wp) why = 'kt must be > 0'
            if (p(2) < 0.0_wp) why = 'mu must be >= 0'
            if (p(3) < 0.0_wp) why = 'normal load fn0 must be >= 0'
        case (LAW_NORMAL1D, LAW_NORMAL2D)
            if (p(1) <= 0.0_wp) why = 'kt must be > 0'
            if (p(2) < 0.0_wp) why = 'kn must be >= 0'
            if (p(3) < 0.0_wp) why = 'mu must be >= 0'
        case (LAW_IWAN4)
            if (p(1) <= 0.0_wp) why = 'fs (the macroslip force) must be > 0'
            if (p(2) <= 0.0_wp) why = 'kt must be > 0'
            if (p(3) <= -1.0_wp) why = 'chi must be > -1'
            if (p(4) < 0.0_wp) why = 'beta must be >= 0'
        case (LAW_IWAN)
            if (any(p(1::2) < 0.0_wp)) why = 'slider stiffnesses k1..k10 must be >= 0'
            if (any(p(2::2) < 0.0_wp)) why = 'slip forces fs1..fs10 must be >= 0'
            if (all(p(1::2) <= 0.0_wp)) why = 'at least one slider stiffness must be > 0'
        end select
    end subroutine check_params

    !> Fractions of the samples of the first m elements of a batch in each contact state,
    !> counted sample by sample over the batch (contiguous, vectorised).
    pure subroutine state_fractions(st, m, frac)
        integer(ip), intent(in) :: st(:, :)   !! (nbatch, N) STATE_* of the batch
        integer(ip), intent(in) :: m
        real(wp), intent(out) :: frac(:, :)   !! (3, m) stick, slip, lift-off
        integer(ip), parameter :: CHUNK = 64
        integer(ip) :: k, j, j0, jm, n, nstick(CHUNK), nslip(CHUNK)
        n = size(st, 2)
        do j0 = 0, m - 1, CHUNK
            jm = min(CHUNK, m - j0)
            nstick(1:jm) = 0
            nslip(1:jm) = 0
            do k = 1, n
                do j = 1, jm
                    nstick(j) = nstick(j) + merge(1_ip, 0_ip, st(j0 + j, k) == STATE_STICK)
                    nslip(j) = nslip(j) + merge(1_ip, 0_ip, st(j0 + j, k) == STATE_SLIP)
                end do
            end do
            do j = 1, jm     ! every sample is in one of the three states
                frac(1, j0 + j) = real(nstick(j), wp)/real(n, wp)
                frac(2, j0 + j) = real(nslip(j), wp)/real(n, wp)
                frac(3, j0 + j) = real(n - nstick(j) - nslip(j), wp)/real(n, wp)
            end do
        end do
    end subroutine state_fractions
end submodule frirom_aft_eval
