!> Alternating frequency/time (AFT): harmonic coefficients of the relative displacements of
!> many contact elements -> harmonic coefficients of their forces, and the analytical
!> Jacobian d(force harmonics)/d(displacement harmonics), one block per element.
!>
!> Method, per batch of elements: displacements to time samples by batched inverse real
!> FFTs; the law is marched (frirom_contact) period after period until the slider returns
!> to where it started (the cycle closes); forces back to harmonics by batched real FFTs.
!> The Jacobian never touches O(N H^2) work: a force that depends on the same-sample
!> displacement with a coefficient c_k contributes the matrix of multiplication by c,
!> built from the 4H+1 trigonometric sums of c; c is constant over runs of samples
!> (kt in stick, +-mu kn in slip, kn in contact), so the sums come from a prefix table
!> in O(H) per run. Dependence on an earlier sample (the slider, fixed at the last slip
!> or lift-off sample, the "anchor") adds a rank-one term per stick segment. The 2-D
!> law, whose slip direction remembers the past, propagates the slider tangent instead.
!>
!> Cost per element: O(N) marching per period (usually 2 periods from a cold slider),
!> one inverse and one forward real FFT of length N per direction, and for the Jacobian
!> an O(N) scan plus O(H^2) per run and per stick segment.
!>
!> Choice of N: N >= 2H+1 is required. Friction laws are non-smooth, so the force
!> harmonics converge like O(N^-2) once the sampling resolves the stick/slip transitions;
!> N = 256 keeps the first harmonics of a Jenkins element within about 1e-5 relative for
!> H <= 7 and is the recommended default; use N >= 4H+1 for the cubic law to be exact.
!> The 2-D law's radial return is first order on curved slip paths (energy error ~ 1/N
!> relative under circular motion): N >= 1024 there.
module frirom_aft
    use frirom_kinds, only: wp, ip
    use frirom_status
    use frirom_fourier
    use frirom_contact
    implicit none
    private

    public :: aft_plan, aft_plan_create, aft_plan_destroy, aft_eval, aft_time
    public :: LAW_JENKINS, LAW_NORMAL1D, LAW_NORMAL2D, LAW_CUBIC
    public :: law_ndir, law_npar, law_nslider

    integer(ip), parameter :: LAW_JENKINS = 1   !! u; kt, mu, fn0
    integer(ip), parameter :: LAW_NORMAL1D = 2  !! u, v; kt, kn, mu, n0
    integer(ip), parameter :: LAW_NORMAL2D = 3  !! u1, u2, v; kt, kn, mu, n0
    integer(ip), parameter :: LAW_CUBIC = 4     !! u; k1, k3
    integer(ip), parameter :: NLAW = 4
    integer(ip), parameter :: NDIR(NLAW) = [1, 2, 3, 1]
    integer(ip), parameter :: NPAR(NLAW) = [3, 4, 4, 2]
    integer(ip), parameter :: NSLIDER(NLAW) = [1, 1, 2, 0]

    integer(ip), parameter :: DEFAULT_BATCH = 16
    real(wp), parameter :: DEFAULT_TOL = 1.0e-12_wp
    integer(ip), parameter :: DEFAULT_MAX_PERIODS = 200

    !> Everything one caller needs to evaluate contact forces at H harmonics and N samples:
    !> FFTW plans, buffers and per-batch work arrays. Owned by the caller (one per thread).
    type :: aft_plan
        type(fourier_plan) :: fp
        integer(ip), allocatable :: state(:, :)      !! (nbatch, N) contact state per sample
        real(wp), allocatable :: tangent(:, :, :)    !! (nbatch, 6, N) 2-D slip tangents
        real(wp), allocatable :: par(:, :)           !! (nbatch, 4) parameters of the batch
        real(wp), allocatable :: w(:, :), wstart(:, :)  !! (nbatch, 2) slider positions
        real(wp), allocatable :: scale(:)            !! (nbatch) closure scale
        integer(ip), allocatable :: closed_at(:)     !! (nbatch) period the cycle closed in
        integer(ip), allocatable :: events(:)        !! (N) slip/lift-off samples of one element
        integer(ip), allocatable :: anchor(:)        !! (nbatch) last slip/lift-off sample
        integer(ip), allocatable :: anchor_state(:)  !! (nbatch) its state
        real(wp), allocatable :: anchor_dtv(:)       !! (nbatch) its d ft / dv
        real(wp), allocatable :: dw(:, :), dw0(:, :) !! (2, 3(2H+1)) 2-D slider tangent
        real(wp), allocatable :: dft(:, :)           !! (2, 3(2H+1)) 2-D force tangent
    end type aft_plan

contains

    pure integer(ip) function law_ndir(law)
        integer(ip), intent(in) :: law
        law_ndir = 0
        if (law >= 1 .and. law <= NLAW) law_ndir = NDIR(law)
    end function law_ndir

    pure integer(ip) function law_npar(law)
        integer(ip), intent(in) :: law
        law_npar = 0
        if (law >= 1 .and. law <= NLAW) law_npar = NPAR(law)
    end function law_npar

    pure integer(ip) function law_nslider(law)
        integer(ip), intent(in) :: law
        law_nslider = 0
        if (law >= 1 .and. law <= NLAW) law_nslider = NSLIDER(law)
    end function law_nslider

    !> Make the plans for H harmonics and N samples (N >= 2H+1), once per run.
    subroutine aft_plan_create(plan, nharm, nsamp, info, errmsg, measure, nbatch)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: nharm                !! H
        integer(ip), intent(in) :: nsamp                !! N
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        logical, intent(in), optional :: measure        !! FFTW_MEASURE (default for N <= 4096;
                                                        !! planning costs once per process and size)
        integer(ip), intent(in), optional :: nbatch     !! elements per batch (default 16)
        logical :: meas
        integer(ip) :: nb, nc
        ! FFTW_MEASURE pays for itself at the sizes Newton loops use; for very long
        ! periods (N > 4096, accuracy studies) its planning time would dominate.
        meas = nsamp <= 4096
        if (present(measure)) meas = measure
        nb = DEFAULT_BATCH
        if (present(nbatch)) nb = max(1_ip, nbatch)
        call aft_plan_destroy(plan)
        call fourier_plan_create(plan%fp, nharm, nsamp, nb, 3_ip, 6_ip, meas, info, errmsg)
        if (info /= FRIROM_OK) return
        nb = plan%fp%nbatch
        nc = plan%fp%ncoef
        allocate (plan%state(nb, nsamp), plan%tangent(nb, 6, nsamp), plan%par(nb, 4))
        allocate (plan%w(nb, 2), plan%wstart(nb, 2), plan%scale(nb), plan%closed_at(nb))
        allocate (plan%anchor(nb), plan%anchor_state(nb), plan%anchor_dtv(nb), plan%events(nsamp))
        allocate (plan%dw(2, 3*nc), plan%dw0(2, 3*nc), plan%dft(2, 3*nc))
    end subroutine aft_plan_create

    subroutine aft_plan_destroy(plan)
        type(aft_plan), intent(inout) :: plan
        call fourier_plan_destroy(plan%fp)
        if (allocated(plan%state)) deallocate (plan%state, plan%par, plan%w, plan%wstart, &
                                                  plan%scale, plan%closed_at)
        if (allocated(plan%anchor)) deallocate (plan%anchor, plan%anchor_state, plan%anchor_dtv, &
                                                   plan%events)
        if (allocated(plan%tangent)) deallocate (plan%tangent)
        if (allocated(plan%dw)) deallocate (plan%dw, plan%dw0, plan%dft)
    end subroutine aft_plan_destroy

    !> Contact forces and (optionally) their Jacobian in harmonic form.
    !>
    !> x(2H+1, ndir, ne): harmonic coefficients of the local relative displacements of ne
    !> elements of one law; f: the forces in the same layout; jac(i, j, e) = d f_i / d x_j
    !> with flat index c + (2H+1)(d-1). w0(nslider, ne): slider position at the start of
    !> the march (0: spring unstretched at zero relative displacement, the configuration
    !> the FE model was built in, so an element stuck all cycle is exactly a linear spring).
    !> The march repeats until the slider closes its cycle to tol (relative to the
    !> displacement amplitude) or max_periods is reached (FRIROM_ERR_NOCLOSE, with the
    !> forces of the last period). periods(e): periods marched; states(:, e): fraction of
    !> samples in stick, slip and lift-off; slider(:, e): slider position with which the
    !> closed cycle starts (= where it ends, after the last sample). A continuation passes slider back as the next point's w0, so that
    !> a contact entering stick-all-cycle keeps the slider where it last slipped (the
    !> stuck state is not unique; history decides it) instead of jumping back to w0.
    subroutine aft_eval(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                        tol, max_periods, index_base, slider)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law                !! LAW_*
        real(wp), intent(in) :: x(:, :, :)            !! (2H+1, ndir, ne), m
        real(wp), intent(in) :: params(:, :)          !! (npar, ne)
        real(wp), intent(in) :: w0(:, :)              !! (nslider, ne), m
        real(wp), intent(out) :: f(:, :, :)           !! (2H+1, ndir, ne), N
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        real(wp), intent(out), optional :: jac(:, :, :)   !! (ndir(2H+1), ndir(2H+1), ne)
        integer(ip), intent(out), optional :: periods(:)  !! (ne)
        real(wp), intent(out), optional :: states(:, :)   !! (3, ne)
        real(wp), intent(in), optional :: tol             !! closure tolerance (1e-12)
        integer(ip), intent(in), optional :: max_periods  !! (200)
        integer(ip), intent(in), optional :: index_base   !! element numbering in messages
        real(wp), intent(out), optional :: slider(:, :)   !! (nslider, ne), m
        integer(ip) :: ne, nd, nc, nb, e0, m, j, e, d, s, np, nper, nfail, base, mp
        real(wp) :: tl
        logical :: want_jac
        character(len=200) :: buf

        call check_call(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                        index_base, slider)
        if (info /= FRIROM_OK) return
        call defaults(tol, max_periods, index_base, tl, mp, base)
        want_jac = present(jac)
        nd = NDIR(law)
        ne = size(x, 3)
        nc = plan%fp%ncoef
        nb = plan%fp%nbatch
        np = nd
        nfail = 0
        if (want_jac) jac = 0.0_wp

        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
            call time_batch(plan, law, x, params, w0, e0, m, tl, mp)
            do j = 1, m
                e = e0 + j - 1
                nper = plan%closed_at(j)
                if (nper > mp .and. nfail == 0) then
                    nfail = e
                    write (buf, '(a,i0,a,i0,a)') 'element ', e - 1 + base, ': not closed after ', &
                        mp, ' periods'
                end if
                if (present(periods)) periods(e) = min(nper, mp)
                if (present(states)) call state_fractions(plan%state(j, :), states(:, e))
                if (present(slider) .and. NSLIDER(law) > 0) &
                    slider(1:NSLIDER(law), e) = plan%w(j, 1:NSLIDER(law))
            end do
            if (want_jac) call fill_series(plan, law, m)
            do s = 1, np
                call exec_r2c(plan%fp, s)
            end do
            do j = 1, m
                e = e0 + j - 1
                do d = 1, nd
                    call harmonics_of(plan%fp, d, j, f(:, d, e))
                end do
                if (want_jac) then
                    select case (law)
                    case (LAW_JENKINS)
                        call jac_friction1d(plan, j, params(1, e), .false., jac(:, :, e))
                    case (LAW_NORMAL1D)
                        call jac_friction1d(plan, j, params(1, e), .true., jac(:, :, e))
                    case (LAW_NORMAL2D)
                        call jac_friction2d(plan, j, params(1, e), w0(:, e), tl, mp, &
                                            jac(:, :, e))
                    case (LAW_CUBIC)
                        call jac_diagonal(plan, j, 2_ip, jac(:, :, e), 0_ip, 0_ip)
                    end select
                end if
            end do
        end do
        if (nfail /= 0) call set_status(info, FRIROM_ERR_NOCLOSE, errmsg, trim(buf))
    end subroutine aft_eval

    !> Time histories of the closed cycle: relative displacements xt and forces ft at the N
    !> samples, for hysteresis loops and contact-state plots.
    subroutine aft_time(plan, law, x, params, w0, xt, ft, info, errmsg, tol, max_periods, &
                        index_base)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: x(:, :, :)     !! (2H+1, ndir, ne)
        real(wp), intent(in) :: params(:, :)   !! (npar, ne)
        real(wp), intent(in) :: w0(:, :)       !! (nslider, ne)
        real(wp), intent(out) :: xt(:, :, :)   !! (N, ndir, ne)
        real(wp), intent(out) :: ft(:, :, :)   !! (N, ndir, ne)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        real(wp), intent(in), optional :: tol
        integer(ip), intent(in), optional :: max_periods
        integer(ip), intent(in), optional :: index_base
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
        nd = NDIR(law)
        ne = size(x, 3)
        nb = plan%fp%nbatch
        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
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
    end subroutine aft_time

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
        if (law < 1 .or. law > NLAW) then
            write (buf, '(a,i0,a)') 'law ', law, ' (expected 1 jenkins, 2 normal1d, 3 normal2d, 4 cubic)'
            call set_status(info, FRIROM_ERR_LAW, errmsg, trim(buf))
            return
        end if
        nc = plan%fp%ncoef
        nd = NDIR(law)
        ne = size(x, 3)
        if (size(x, 1) /= nc .or. size(x, 2) /= nd) then
            write (buf, '(a,i0,a,i0,a,i0,a,i0,a)') 'x is (', size(x, 1), ', ', size(x, 2), &
                ', ne); expected (2H+1 = ', nc, ', ndir = ', nd, ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        else if (any(shape(f) /= shape(x))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'f must have the shape of x')
        else if (size(params, 1) /= NPAR(law) .or. size(params, 2) /= ne) then
            write (buf, '(a,i0,a,i0,a,i0,a)') 'params is (', size(params, 1), ', ', &
                size(params, 2), '); expected (', NPAR(law), ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        else if (size(w0, 1) < NSLIDER(law) .or. (NSLIDER(law) > 0 .and. size(w0, 2) /= ne)) then
            write (buf, '(a,i0,a)') 'w0 must be (', NSLIDER(law), ', ne)'
            call set_status(info, FRIROM_ERR_SIZE, errmsg, trim(buf))
        end if
        if (info /= FRIROM_OK) return
        if (present(jac)) then
            if (size(jac, 1) /= nc*nd .or. size(jac, 2) /= nc*nd .or. size(jac, 3) /= ne) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'jac must be (ndir(2H+1), ndir(2H+1), ne)')
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
            if (size(slider, 1) < NSLIDER(law) .or. size(slider, 2) /= ne) then
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
            if (NSLIDER(law) > 0) then
                if (.not. all(abs(w0(1:NSLIDER(law), e)) <= huge(1.0_wp))) then
                    write (buf, '(a,i0,a)') 'initial slider of element ', e - 1 + base, ' is not finite'
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
        end select
    end subroutine check_params

    !> Elements e0..e0+m-1: displacement harmonics to time samples (input slots), then
    !> the law marched until their cycles close (see march_closed).
    subroutine time_batch(plan, law, x, params, w0, e0, m, tol, max_periods)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, e0, m, max_periods
        real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :), tol
        integer(ip) :: d, j
        do d = 1, NDIR(law)
            call clear_input(plan%fp, d)
            do j = 1, m
                call load_harmonics(plan%fp, d, j, x(:, d, e0 + j - 1))
            end do
            call exec_c2r(plan%fp, d)
        end do
        call march_closed(plan, law, m, params(:, e0:e0 + m - 1), w0(:, e0:e0 + m - 1), tol, &
                          max_periods)
    end subroutine time_batch

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
                   w => plan%w(1:m, :), par => plan%par(1:m, :))
            ns = NSLIDER(law)
            do i = 1, NPAR(law)
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
                do d = 1, NDIR(law)
                    plan%scale(j) = max(plan%scale(j), maxval(abs(rin(j, :, d))))
                end do
            end do
            plan%closed_at(1:m) = max_periods + 1
            do nper = 1, max_periods
                plan%wstart(1:m, :) = w
                select case (law)
                case (LAW_JENKINS)
                    call jenkins_march(rin(1:m, :, 1), par(:, 1), par(:, 2), par(:, 3), w(:, 1), &
                                       rout(1:m, :, 1), st)
                case (LAW_NORMAL1D)
                    call friction1d_march(rin(1:m, :, 1), rin(1:m, :, 2), par(:, 1), par(:, 2), &
                                          par(:, 3), par(:, 4), w(:, 1), rout(1:m, :, 1), &
                                          rout(1:m, :, 2), st, rout(1:m, :, 4))
                case (LAW_NORMAL2D)
                    call friction2d_march(rin(1:m, :, 1), rin(1:m, :, 2), rin(1:m, :, 3), &
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

    !> Same-sample coefficient series of the Jacobian, written after the forces:
    !> Jenkins slot 2 = kt [stick]; normal1d slot 3 = kt [stick], slot 4 = d ft/dv (the
    !> march wrote it), slot 5 = kn [contact]; normal2d slot 4 = kt [stick], slot 5 = kn
    !> [contact]; cubic slot 2 = df/du (the spring wrote it).
    pure subroutine fill_series(plan, law, m)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, m
        integer(ip) :: k
        associate (rout => plan%fp%rout, st => plan%state, par => plan%par)
            do k = 1, plan%fp%nsamp
                select case (law)
                case (LAW_JENKINS)
                    rout(1:m, k, 2) = merge(par(1:m, 1), 0.0_wp, st(1:m, k) == STATE_STICK)
                case (LAW_NORMAL1D)
                    rout(1:m, k, 3) = merge(par(1:m, 1), 0.0_wp, st(1:m, k) == STATE_STICK)
                    rout(1:m, k, 5) = merge(par(1:m, 2), 0.0_wp, st(1:m, k) /= STATE_LIFTOFF)
                case (LAW_NORMAL2D)
                    rout(1:m, k, 4) = merge(par(1:m, 1), 0.0_wp, st(1:m, k) == STATE_STICK)
                    rout(1:m, k, 5) = merge(par(1:m, 2), 0.0_wp, st(1:m, k) /= STATE_LIFTOFF)
                end select
            end do
        end associate
    end subroutine fill_series

    pure subroutine state_fractions(st, frac)
        integer(ip), intent(in) :: st(:)
        real(wp), intent(out) :: frac(3)  !! stick, slip, lift-off
        frac(1) = real(count(st == STATE_STICK), wp)/real(size(st), wp)
        frac(2) = real(count(st == STATE_SLIP), wp)/real(size(st), wp)
        frac(3) = real(count(st == STATE_LIFTOFF), wp)/real(size(st), wp)
    end subroutine state_fractions

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
    !> Stick samples after anchor a: f_t(k) = kt (u_k - u_a) + f_t(a), where f_t(a) =
    !> s mu (n0 + kn v_a) at a slip anchor and 0 at a lift-off anchor; slip: f_t(k) =
    !> s mu (n0 + kn v_k); f_n(k) = n0 + kn v_k in contact. The anchor of the first stick
    !> samples is the last anchor of the period, since the cycle is closed.
    subroutine jac_friction1d(plan, j, kt, normal, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        logical, intent(in) :: normal
        real(wp), intent(inout) :: jac(:, :)  !! (nd nc, nd nc)
        integer(ip) :: n, nc, nh, k, k0, a, nev, i, i1, i2, c
        real(wp) :: g(plan%fp%ncoef), dtv, kn
        real(wp), dimension(0:2*plan%fp%nharm) :: ctu, stu, ctv, stv, cnv, snv
        n = plan%fp%nsamp
        nc = plan%fp%ncoef
        nh = plan%fp%nharm
        kn = plan%par(j, 2)
        ctu = 0.0_wp; stu = 0.0_wp; ctv = 0.0_wp; stv = 0.0_wp; cnv = 0.0_wp; snv = 0.0_wp
        associate (st => plan%state, bas => plan%fp%basis, ev => plan%events, &
                   dtvs => plan%fp%rout(j, :, 4))
            ! One pass: runs of equal state (and slip sign) give the trig sums of the
            ! same-sample series kt [stick], d ft/dv [slip], kn [contact]; events are the
            ! slip and lift-off samples that anchor the following stick segments.
            nev = 0
            k0 = 1
            do k = 1, n + 1
                if (k <= n) then
                    if (st(j, k) /= STATE_STICK) then
                        nev = nev + 1
                        ev(nev) = k
                    end if
                    if (st(j, k) == st(j, k0)) then
                        if (.not. (normal .and. st(j, k) == STATE_SLIP)) cycle
                        if (dtvs(k) == dtvs(k0)) cycle
                    end if
                end if
                select case (st(j, k0))
                case (STATE_STICK)
                    call add_run(kt, k0, k - 1, ctu, stu)
                    if (normal) call add_run(kn, k0, k - 1, cnv, snv)
                case (STATE_SLIP)
                    if (normal) then
                        call add_run(dtvs(k0), k0, k - 1, ctv, stv)
                        call add_run(kn, k0, k - 1, cnv, snv)
                    end if
                end select
                k0 = k
            end do
            call toeplitz_add(nh, n, ctu, stu, jac, 0_ip, 0_ip)
            if (normal) then
                call toeplitz_add(nh, n, ctv, stv, jac, 0_ip, nc)
                call toeplitz_add(nh, n, cnv, snv, jac, nc, nc)
            end if
            if (nev == 0) then
                ! Stuck all cycle. If the slider moved while the march settled, every
                ! sample is anchored there: the whole-period sum of P is the mean row.
                a = plan%anchor(j)
                if (a == 0) return
                jac(1, 1:nc) = jac(1, 1:nc) - kt*bas(a, :)
                if (normal .and. plan%anchor_state(j) == STATE_SLIP) &
                    jac(1, nc + 1:2*nc) = jac(1, nc + 1:2*nc) + plan%anchor_dtv(j)*bas(a, :)
                return
            end if
            do i = 1, nev
                ! stick segment after event a, up to the next event (cyclic)
                a = ev(i)
                i1 = mod(a, n) + 1
                if (i < nev) then
                    i2 = ev(i + 1) - 1
                else
                    i2 = ev(1) - 1
                    if (i2 == 0) i2 = n
                end if
                if ((i < nev .and. i2 < i1) .or. (i == nev .and. i1 == ev(1))) cycle
                call segment_sum(plan%fp, i1, i2, g)
                do c = 1, nc
                    jac(1:nc, c) = jac(1:nc, c) - kt*bas(a, c)*g
                end do
                if (normal .and. st(j, a) == STATE_SLIP) then
                    dtv = dtvs(a)
                    do c = 1, nc
                        jac(1:nc, nc + c) = jac(1:nc, nc + c) + dtv*bas(a, c)*g
                    end do
                end if
            end do
        end associate
    contains
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

    !> Jacobian of the 2-D element. The slip direction depends on the whole history, so
    !> the slider tangent dw (2 x 3(2H+1)) is propagated through the period, repeated until
    !> it closes (slip contracts it; lift-off resets it), then once more accumulating.
    !> The propagation starts from the tangent the settling periods leave (marched again
    !> from w0): a contact that slipped while the march settled and then sticks all cycle,
    !> or only touches the friction limit, keeps a slider that depends on that history
    !> (along the limit circle the recursion does not contract).
    subroutine jac_friction2d(plan, j, kt, w0j, tol, max_periods, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j, max_periods
        real(wp), intent(in) :: kt, tol
        real(wp), intent(in) :: w0j(:)        !! (2) the element's initial slider
        real(wp), intent(inout) :: jac(:, :)  !! (3 nc, 3 nc)
        integer(ip) :: nc, pass
        nc = plan%fp%ncoef
        call jac_diagonal(plan, j, 4_ip, jac, 0_ip, 0_ip)       ! d f1/du1, stick
        call jac_diagonal(plan, j, 4_ip, jac, nc, nc)           ! d f2/du2, stick
        call jac_diagonal(plan, j, 5_ip, jac, 2*nc, 2*nc)       ! d fn/dv, contact
        plan%dw = 0.0_wp
        if (plan%closed_at(j) > 1 .and. any(plan%w(j, 1:2) /= w0j(1:2))) &
            call settle2d(plan, j, kt, w0j, jac)
        if (all(plan%state(j, :) == STATE_STICK)) then
            if (any(plan%dw /= 0.0_wp)) call propagate2d(plan, j, kt, .true., jac)
            return
        end if
        do pass = 1, max_periods
            plan%dw0 = plan%dw
            call propagate2d(plan, j, kt, .false., jac)
            if (maxval(abs(plan%dw - plan%dw0)) <= tol*max(1.0_wp, maxval(abs(plan%dw)))) exit
        end do
        call propagate2d(plan, j, kt, .true., jac)
    end subroutine jac_friction2d

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
        allocate (st(1, n), w(1, 2), f(1, n, 3), tg(1, 6, n))
        st_keep = plan%state(j, :)
        tg_keep = plan%tangent(j, :, :)
        w(1, :) = w0j(1:2)
        plan%dw = 0.0_wp
        associate (rin => plan%fp%rin, par => plan%par)
            do per = 1, plan%closed_at(j) - 1
                call friction2d_march(rin(j:j, :, 1), rin(j:j, :, 2), rin(j:j, :, 3), &
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
    !> stick: d f = kt (dU_k - dw), dw kept; slip: d f = A_k (dU_k - dw) + b_k dV_k,
    !> dw = dU_k - d f / kt; lift-off: d f = 0, dw = dU_k. The same-sample stick part is in
    !> the Toeplitz blocks already; here only the terms in dw and the slip samples.
    subroutine propagate2d(plan, j, kt, accumulate, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        logical, intent(in) :: accumulate
        real(wp), intent(inout) :: jac(:, :)
        integer(ip) :: n, nc, k, i, c
        real(wp) :: gsum(plan%fp%ncoef), pk(plan%fp%ncoef)
        logical :: open_seg
        n = plan%fp%nsamp
        nc = plan%fp%ncoef
        associate (st => plan%state(j, :), tg => plan%tangent(j, :, :), bas => plan%fp%basis, &
                   wgt => plan%fp%weight, dw => plan%dw, dft => plan%dft)
            gsum = 0.0_wp
            open_seg = .false.
            do k = 1, n
                if (st(k) == STATE_STICK) then
                    if (accumulate) gsum = gsum + wgt*bas(k, :)
                    open_seg = .true.
                    cycle
                end if
                if (open_seg .and. accumulate) call flush_stick(gsum)
                open_seg = .false.
                if (st(k) == STATE_SLIP) then
                    dft(1, :) = -(tg(1, k)*dw(1, :) + tg(3, k)*dw(2, :))
                    dft(2, :) = -(tg(2, k)*dw(1, :) + tg(4, k)*dw(2, :))
                    dft(1, 1:nc) = dft(1, 1:nc) + tg(1, k)*bas(k, :)
                    dft(2, 1:nc) = dft(2, 1:nc) + tg(2, k)*bas(k, :)
                    dft(1, nc + 1:2*nc) = dft(1, nc + 1:2*nc) + tg(3, k)*bas(k, :)
                    dft(2, nc + 1:2*nc) = dft(2, nc + 1:2*nc) + tg(4, k)*bas(k, :)
                    dft(1, 2*nc + 1:3*nc) = dft(1, 2*nc + 1:3*nc) + tg(5, k)*bas(k, :)
                    dft(2, 2*nc + 1:3*nc) = dft(2, 2*nc + 1:3*nc) + tg(6, k)*bas(k, :)
                    if (accumulate) then
                        pk = wgt*bas(k, :)
                        do i = 1, 2
                            do c = 1, 3*nc
                                jac((i - 1)*nc + 1:i*nc, c) = jac((i - 1)*nc + 1:i*nc, c) &
                                                              + pk*dft(i, c)
                            end do
                        end do
                    end if
                    dw = -dft/kt
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
    end subroutine propagate2d
end module frirom_aft
