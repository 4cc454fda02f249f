!> Alternating frequency/time (AFT): harmonic coefficients of the relative displacements of
!> many contact elements -> harmonic coefficients of their forces, and the analytical
!> Jacobian d(force harmonics)/d(displacement harmonics), one block per element.
!>
!> Method, per batch of elements: displacements to time samples by batched inverse real
!> FFTs; the law is marched (frirom_contact) period after period until the slider returns
!> to where it started (the cycle closes); forces back to harmonics by batched real FFTs.
!> The Jacobian never touches O(N H^2) work: a force that depends on the same-sample
!> displacement with a coefficient c_k contributes the matrix of multiplication by c,
!> built from the 2H+1 trigonometric sums of c (one more batched FFT); dependence on an
!> earlier sample (the slider, fixed at the last slip or lift-off sample "anchor") adds a
!> rank-one term per stick segment. The 2-D law, whose slip direction remembers the past,
!> propagates the slider tangent through the period instead.
!>
!> Cost per element: O(N) marching per period (usually 1-2 periods) plus a few real FFTs
!> of length N; the Jacobian adds one to three FFTs and O(H^2) per stick segment.
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
    ! Output slot of the same-sample coefficient series of each law (after the forces).
    integer(ip), parameter :: NSERIES(NLAW) = [1, 3, 2, 1]

    integer(ip), parameter :: DEFAULT_BATCH = 16
    real(wp), parameter :: DEFAULT_TOL = 1.0e-12_wp
    integer(ip), parameter :: DEFAULT_MAX_PERIODS = 200

    !> Everything one caller needs to evaluate contact forces at H harmonics and N samples:
    !> FFTW plans, buffers and per-batch work arrays. Owned by the caller (one per thread).
    type :: aft_plan
        type(fourier_plan) :: fp
        integer(ip), allocatable :: state(:, :)      !! (N, nbatch) contact state per sample
        real(wp), allocatable :: tangent(:, :, :)    !! (6, N, nbatch) 2-D slip tangents
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
        logical, intent(in), optional :: measure        !! FFTW_MEASURE (slower to plan)
        integer(ip), intent(in), optional :: nbatch     !! elements per batch (default 16)
        logical :: meas
        integer(ip) :: nb, nc
        meas = .false.
        if (present(measure)) meas = measure
        nb = DEFAULT_BATCH
        if (present(nbatch)) nb = max(1_ip, nbatch)
        call aft_plan_destroy(plan)
        call fourier_plan_create(plan%fp, nharm, nsamp, nb, 3_ip, 6_ip, meas, info, errmsg)
        if (info /= FRIROM_OK) return
        nb = plan%fp%nbatch
        nc = plan%fp%ncoef
        allocate (plan%state(nsamp, nb), plan%tangent(6, nsamp, nb))
        allocate (plan%dw(2, 3*nc), plan%dw0(2, 3*nc), plan%dft(2, 3*nc))
    end subroutine aft_plan_create

    subroutine aft_plan_destroy(plan)
        type(aft_plan), intent(inout) :: plan
        call fourier_plan_destroy(plan%fp)
        if (allocated(plan%state)) deallocate (plan%state)
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
    !> samples in stick, slip and lift-off.
    subroutine aft_eval(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                        tol, max_periods, index_base)
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
        integer(ip) :: ne, nd, nc, nb, e0, m, j, e, d, s, np, nper, nfail, base, mp
        real(wp) :: tl
        logical :: want_jac
        character(len=200) :: buf

        call check_call(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                        index_base)
        if (info /= FRIROM_OK) return
        tl = DEFAULT_TOL
        if (present(tol)) tl = tol
        mp = DEFAULT_MAX_PERIODS
        if (present(max_periods)) mp = max_periods
        base = 1
        if (present(index_base)) base = index_base
        want_jac = present(jac)
        nd = NDIR(law)
        ne = size(x, 3)
        nc = plan%fp%ncoef
        nb = plan%fp%nbatch
        np = nd
        if (want_jac) np = nd + NSERIES(law)
        nfail = 0
        if (want_jac) jac = 0.0_wp

        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
            do d = 1, nd
                do j = 1, m
                    call load_harmonics(plan%fp, d, j, x(:, d, e0 + j - 1))
                end do
                call exec_c2r(plan%fp, d)
            end do
            do j = 1, m
                e = e0 + j - 1
                call march_closed(plan, law, j, params(:, e), w0(:, e), tl, mp, nper)
                if (nper > mp .and. nfail == 0) then
                    nfail = e
                    write (buf, '(a,i0,a,i0,a)') 'element ', e - 1 + base, ': not closed after ', &
                        mp, ' periods'
                end if
                if (present(periods)) periods(e) = min(nper, mp)
                if (want_jac) call fill_series(plan, law, j, params(:, e))
                if (present(states)) call state_fractions(plan%state(:, j), states(:, e))
            end do
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
                        call jac_friction2d(plan, j, params(1, e), tl, mp, jac(:, :, e))
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
        integer(ip) :: ne, nd, nb, e0, m, j, e, d, nper, mp, base
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
        tl = DEFAULT_TOL
        if (present(tol)) tl = tol
        mp = DEFAULT_MAX_PERIODS
        if (present(max_periods)) mp = max_periods
        base = 1
        if (present(index_base)) base = index_base
        nd = NDIR(law)
        ne = size(x, 3)
        nb = plan%fp%nbatch
        do e0 = 1, ne, nb
            m = min(nb, ne - e0 + 1)
            do d = 1, nd
                do j = 1, m
                    call load_harmonics(plan%fp, d, j, x(:, d, e0 + j - 1))
                end do
                call exec_c2r(plan%fp, d)
            end do
            do j = 1, m
                e = e0 + j - 1
                call march_closed(plan, law, j, params(:, e), w0(:, e), tl, mp, nper)
                if (nper > mp .and. info == FRIROM_OK) then
                    info = FRIROM_ERR_NOCLOSE
                    if (present(errmsg)) write (errmsg, '(a,a,i0)') &
                        frirom_status_message(info), ': element ', e - 1 + base
                end if
                do d = 1, nd
                    xt(:, d, e) = plan%fp%rin(:, j, d)
                    ft(:, d, e) = plan%fp%rout(:, j, d)
                end do
            end do
        end do
    end subroutine aft_time

    !> Shapes, law and parameters of an AFT call, checked before any work.
    subroutine check_call(plan, law, x, params, w0, f, info, errmsg, jac, periods, states, &
                          index_base)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: law
        real(wp), intent(in) :: x(:, :, :), params(:, :), w0(:, :), f(:, :, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        real(wp), intent(in), optional :: jac(:, :, :)
        integer(ip), intent(in), optional :: periods(:)
        real(wp), intent(in), optional :: states(:, :)
        integer(ip), intent(in), optional :: index_base
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

    !> March batch column j period after period until the slider closes its cycle; the
    !> last period's forces (output slots 1..ndir), states and tangents stay in the plan.
    !> nper = periods marched, or max_periods + 1 when the cycle did not close.
    subroutine march_closed(plan, law, j, p, w0, tol, max_periods, nper)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, j
        real(wp), intent(in) :: p(:), w0(:), tol
        integer(ip), intent(in) :: max_periods
        integer(ip), intent(out) :: nper
        real(wp) :: w(2), wstart(2), scale
        integer(ip) :: ns, d
        associate (rin => plan%fp%rin, rout => plan%fp%rout, st => plan%state(:, j))
            ns = NSLIDER(law)
            if (law == LAW_CUBIC) then
                call cubic_spring(rin(:, j, 1), p(1), p(2), rout(:, j, 1), rout(:, j, 2))
                st = STATE_STICK
                nper = 1
                return
            end if
            w = 0.0_wp
            w(1:ns) = w0(1:ns)
            scale = tiny(1.0_wp)
            do d = 1, NDIR(law)
                scale = max(scale, maxval(abs(rin(:, j, d))))
            end do
            scale = max(scale, maxval(abs(w(1:ns))))
            do nper = 1, max_periods
                wstart = w
                select case (law)
                case (LAW_JENKINS)
                    call jenkins_march(rin(:, j, 1), p(1), p(2), p(3), w(1), rout(:, j, 1), st)
                case (LAW_NORMAL1D)
                    call friction1d_march(rin(:, j, 1), rin(:, j, 2), p(1), p(2), p(3), p(4), &
                                          w(1), rout(:, j, 1), rout(:, j, 2), st, rout(:, j, 4))
                case (LAW_NORMAL2D)
                    call friction2d_march(rin(:, j, 1), rin(:, j, 2), rin(:, j, 3), p(1), p(2), &
                                          p(3), p(4), w, rout(:, j, 1), rout(:, j, 2), &
                                          rout(:, j, 3), st, plan%tangent(:, :, j))
                end select
                if (maxval(abs(w(1:ns) - wstart(1:ns))) <= tol*scale) return
            end do
            nper = max_periods + 1
        end associate
    end subroutine march_closed

    !> Same-sample coefficient series of the Jacobian, written after the forces:
    !> Jenkins slot 2 = kt [stick]; normal1d slot 3 = kt [stick], slot 4 = d ft/dv (the
    !> march wrote it), slot 5 = kn [contact]; normal2d slot 4 = kt [stick], slot 5 = kn
    !> [contact]; cubic slot 2 = df/du (the spring wrote it).
    pure subroutine fill_series(plan, law, j, p)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: law, j
        real(wp), intent(in) :: p(:)
        associate (rout => plan%fp%rout, st => plan%state(:, j))
            select case (law)
            case (LAW_JENKINS)
                rout(:, j, 2) = merge(p(1), 0.0_wp, st == STATE_STICK)
            case (LAW_NORMAL1D)
                rout(:, j, 3) = merge(p(1), 0.0_wp, st == STATE_STICK)
                rout(:, j, 5) = merge(p(2), 0.0_wp, st /= STATE_LIFTOFF)
            case (LAW_NORMAL2D)
                rout(:, j, 4) = merge(p(1), 0.0_wp, st == STATE_STICK)
                rout(:, j, 5) = merge(p(2), 0.0_wp, st /= STATE_LIFTOFF)
            end select
        end associate
    end subroutine fill_series

    pure subroutine state_fractions(st, frac)
        integer(ip), intent(in) :: st(:)
        real(wp), intent(out) :: frac(3)  !! stick, slip, lift-off
        frac(1) = real(count(st == STATE_STICK), wp)/real(size(st), wp)
        frac(2) = real(count(st == STATE_SLIP), wp)/real(size(st), wp)
        frac(3) = real(count(st == STATE_LIFTOFF), wp)/real(size(st), wp)
    end subroutine state_fractions

    !> Add the multiplication matrix of the series in output slot `slot` to the block at
    !> (r0, c0) of jac.
    pure subroutine jac_diagonal(plan, j, slot, jac, r0, c0)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: j, slot, r0, c0
        real(wp), intent(inout) :: jac(:, :)
        real(wp) :: cm(0:2*plan%fp%nharm), sm(0:2*plan%fp%nharm)
        call trig_sums(plan%fp, slot, j, cm, sm)
        call toeplitz_add(plan%fp%nharm, plan%fp%nsamp, cm, sm, jac, r0, c0)
    end subroutine jac_diagonal

    !> Jacobian of the Jenkins (normal = .false.) or 1-D normal-load element.
    !> Stick samples after anchor a: f_t(k) = kt (u_k - u_a) + f_t(a), where f_t(a) =
    !> s mu kn v_a at a slip anchor and 0 at a lift-off anchor; slip: f_t(k) = s mu (n0 + kn v_k);
    !> f_n(k) = n0 + kn v_k in contact. The anchor of the first stick samples is the last
    !> anchor of the period, since the cycle is closed.
    pure subroutine jac_friction1d(plan, j, kt, normal, jac)
        type(aft_plan), intent(in) :: plan
        integer(ip), intent(in) :: j
        real(wp), intent(in) :: kt
        logical, intent(in) :: normal
        real(wp), intent(inout) :: jac(:, :)  !! (nd nc, nd nc)
        integer(ip) :: n, nc, k, a, last, step, i1, i2, c
        real(wp) :: g(plan%fp%ncoef), dtv
        n = plan%fp%nsamp
        nc = plan%fp%ncoef
        associate (st => plan%state(:, j), bas => plan%fp%basis)
            if (normal) then
                call jac_diagonal(plan, j, 3_ip, jac, 0_ip, 0_ip)     ! d ft / du, stick
                call jac_diagonal(plan, j, 4_ip, jac, 0_ip, nc)       ! d ft / dv, slip
                call jac_diagonal(plan, j, 5_ip, jac, nc, nc)         ! d fn / dv, contact
            else
                call jac_diagonal(plan, j, 2_ip, jac, 0_ip, 0_ip)
            end if
            last = 0
            do k = n, 1, -1
                if (st(k) /= STATE_STICK) then
                    last = k
                    exit
                end if
            end do
            if (last == 0) return   ! stuck all cycle: the slider never moved
            a = last
            do step = 1, n
                k = mod(last + step - 1, n) + 1
                if (st(k) == STATE_STICK) cycle
                ! stick segment a+1 .. k-1 (cyclic), anchored at a
                i1 = mod(a, n) + 1
                i2 = k - 1
                if (i2 == 0) i2 = n
                if (i1 /= k) then
                    call segment_sum(plan%fp, i1, i2, g)
                    do c = 1, nc
                        jac(1:nc, c) = jac(1:nc, c) - kt*bas(a, c)*g
                    end do
                    if (normal .and. st(a) == STATE_SLIP) then
                        dtv = plan%fp%rout(a, j, 4)
                        do c = 1, nc
                            jac(1:nc, nc + c) = jac(1:nc, nc + c) + dtv*bas(a, c)*g
                        end do
                    end if
                end if
                a = k
            end do
        end associate
    end subroutine jac_friction1d

    !> Jacobian of the 2-D element. The slip direction depends on the whole history, so
    !> the slider tangent dw (2 x 3(2H+1)) is propagated through the period, repeated until
    !> it closes (slip contracts it; lift-off resets it), then once more accumulating.
    subroutine jac_friction2d(plan, j, kt, tol, max_periods, jac)
        type(aft_plan), intent(inout) :: plan
        integer(ip), intent(in) :: j, max_periods
        real(wp), intent(in) :: kt, tol
        real(wp), intent(inout) :: jac(:, :)  !! (3 nc, 3 nc)
        integer(ip) :: nc, pass
        nc = plan%fp%ncoef
        call jac_diagonal(plan, j, 4_ip, jac, 0_ip, 0_ip)       ! d f1/du1, stick
        call jac_diagonal(plan, j, 4_ip, jac, nc, nc)           ! d f2/du2, stick
        call jac_diagonal(plan, j, 5_ip, jac, 2*nc, 2*nc)       ! d fn/dv, contact
        if (all(plan%state(:, j) == STATE_STICK)) return
        plan%dw = 0.0_wp
        do pass = 1, max_periods
            plan%dw0 = plan%dw
            call propagate2d(plan, j, kt, .false., jac)
            if (maxval(abs(plan%dw - plan%dw0)) <= tol*max(1.0_wp, maxval(abs(plan%dw)))) exit
        end do
        call propagate2d(plan, j, kt, .true., jac)
    end subroutine jac_friction2d

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
        associate (st => plan%state(:, j), tg => plan%tangent(:, :, j), bas => plan%fp%basis, &
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
