!> Setup and run driver of frirom_hbm: hbm_setup builds either formulation from plain
!> arrays, hbm_run solves and continues it point by point; the small helpers every
!> formulation uses (wall clock, frequency and load factor at lam).
submodule (frirom_hbm) frirom_hbm_run
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_ALLOC, &
                             FRIROM_ERR_MODEL, FRIROM_ERR_LAW, set_status
    use frirom_newton, only: newton_correct, cont_tangent, cont_run
    use frirom_aft, only: aft_plan_create, law_ndir, law_npar, law_nslider, law_rest_force, &
                          law_check
    implicit none

contains

    module procedure hbm_roundoff
        real(wp) :: r0, rd, tiny_r
        integer(ip) :: n0
        tiny_r = 100.0_wp*epsilon(1.0_wp)
        if (this%rref_dyn < 0.0_wp) then
            yes = norm2(r) <= tiny_r*rref
            return
        end if
        select type (this)
        type is (hbm_condensed)
            ! harmonic by harmonic, harmonic 0 first: nnl unknowns each, or with a
            ! selection (hbm_set_selection) the kept ones of harmonic 0
            n0 = this%nnl
            if (allocated(this%sel)) n0 = this%kptr(2) - this%kptr(1)
            r0 = norm2(r(1:n0))
            rd = norm2(r(n0 + 1:))
        class default
            ! DoF by DoF, nc harmonics each: harmonic 0 first
            associate (rr => reshape(r, [this%nc, size(r)/this%nc]))
                r0 = norm2(rr(1, :))
                rd = norm2(rr(2:, :))
            end associate
        end select
        yes = r0 <= tiny_r*rref .and. rd <= tiny_r*this%rref_dyn
    end procedure hbm_roundoff

    module procedure hbm_setup
        integer(ip) :: nc, ng, g, nrows, row, ip0, iw0, npar, nsl, ne, nd, i, k, ncol, nnl
        integer(ip), allocatable :: colmap(:), gi2(:)
        integer(ip) :: stat
        info = FRIROM_OK
        nc = 2*nh + 1
        if (nh < 0 .or. ndof < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: need H >= 0, ndof >= 1')
            return
        end if
        if (size(perm) /= ndof .or. size(fe0, 1) /= ndof .or. size(fe0, 2) /= nc .or. &
            any(shape(fe1) /= shape(fe0))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: perm or excitation size')
            return
        end if
        if (mode /= HBM_FREQUENCY .and. mode /= HBM_LOAD) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: mode must be 1 or 2')
            return
        end if
        sys%nh = nh
        sys%nc = nc
        sys%ndof = ndof
        sys%mode = mode
        sys%omega_fix = omega_fix
        call csr_set(sys%k, ndof, ndof, kp, ki, kx, 'K', info, errmsg)
        if (info /= 0) return
        call csr_set(sys%m, ndof, ndof, mp, mi, mx, 'M', info, errmsg)
        if (info /= 0) return
        call csr_set(sys%c, ndof, ndof, cp, ci, cx, 'C', info, errmsg)
        if (info /= 0) return
        allocate (sys%iperm(ndof))
        sys%perm = perm
        sys%iperm = 0
        do i = 1, ndof
            if (perm(i) < 1 .or. perm(i) > ndof) exit
            sys%iperm(perm(i)) = i
        end do
        if (any(sys%iperm == 0)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: perm is not a '// &
                            'permutation of 1..ndof')
            return
        end if
        sys%fe0 = fe0
        sys%fe1 = fe1
        if (any(outdofs < 1) .or. any(outdofs > ndof)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: output DoF out of range')
            return
        end if
        sys%outdofs = outdofs
        ! bandwidth of K, M, C and the contact couplings under perm
        sys%bw = max(pattern_bw(sys%k), pattern_bw(sys%m), pattern_bw(sys%c))
        ! contact groups; the condensed formulation renumbers G's columns to nl
        ng = size(ginfo, 2)
        nrows = 0
        do g = 1, ng
            if (size(ginfo, 1) < 3) exit
            nrows = nrows + ginfo(2, g)*ginfo(3, g)
        end do
        if (size(ginfo, 1) < 3 .or. size(gp) /= nrows + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: G rows do not match '// &
                            'the contact groups')
            return
        end if
        select type (sys)
        type is (hbm_condensed)
            nnl = size(nl)
            if (nnl < 1) then
                call set_status(info, FRIROM_ERR_MODEL, errmsg, 'hbm_setup: the condensed '// &
                                'formulation needs at least one contact DoF')
                return
            end if
            allocate (colmap(ndof))
            colmap = 0
            do i = 1, nnl
                if (nl(i) < 1 .or. nl(i) > ndof) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'hbm_setup: nl out of range')
                    return
                end if
                colmap(nl(i)) = i
            end do
            k = gp(nrows + 1) - 1
            if (k > size(gi) .or. k < 0) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: G pointers')
                return
            end if
            allocate (gi2(k))
            do i = 1, k
                if (gi(i) < 1 .or. gi(i) > ndof) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'G: column out of range')
                    return
                end if
                gi2(i) = colmap(gi(i))
                if (gi2(i) == 0) then
                    call set_status(info, FRIROM_ERR_MODEL, errmsg, 'hbm_setup: a column of '// &
                                    'G is missing from the nonlinear DoF list')
                    return
                end if
            end do
            sys%tcontact = .false.
            if (present(contact_coords)) sys%tcontact = contact_coords
            if (present(krylov)) sys%krylov = krylov
            if (present(sparse_lu)) sys%sparse_lu = sparse_lu
            if (sys%tcontact) then
                ! u = G x: T = G, and the contacts read u directly (G over u = I)
                ncol = nrows
                call csr_set(sys%t, nrows, ndof, gp, gi, gx, 'G', info, errmsg)
                if (info /= 0) return
                call csr_set(sys%cs%g, nrows, ncol, [(i, i=1, nrows + 1)], [(i, i=1, nrows)], &
                             [(1.0_wp, i=1, nrows)], 'G', info, errmsg)
            else
                ! u = P x: T selects the nl DoFs, G's columns renumbered to them
                ncol = nnl
                call csr_set(sys%t, nnl, ndof, [(i, i=1, nnl + 1)], nl, [(1.0_wp, i=1, nnl)], &
                             'T', info, errmsg)
                if (info /= 0) return
                call csr_set(sys%cs%g, nrows, ncol, gp, gi2, gx, 'G', info, errmsg)
            end if
        class default
            ncol = ndof
            call csr_set(sys%cs%g, nrows, ncol, gp, gi, gx, 'G', info, errmsg)
        end select
        if (info /= 0) return
        sys%cs%nc = nc
        allocate (sys%xd(ncol, nc), sys%fd(ncol, nc), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_setup: contact columns')
            return
        end if
        allocate (sys%cs%grp(ng))
        row = 0
        ip0 = 0
        iw0 = 0
        do g = 1, ng
            associate (gr => sys%cs%grp(g))
                gr%law = ginfo(1, g)
                ne = ginfo(2, g)
                nd = ginfo(3, g)
                call law_check(gr%law, info, errmsg, user=.true.)
                if (info /= 0) return
                if (nd /= law_ndir(gr%law) .or. ne < 1) then
                    call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: contact group '// &
                                    'directions do not match its law, or no element')
                    return
                end if
                npar = law_npar(gr%law)
                nsl = law_nslider(gr%law)
                if (ip0 + npar*ne > size(params) .or. iw0 + nsl*ne > size(w0)) then
                    call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_setup: params or w0 '// &
                                    'shorter than the groups need')
                    return
                end if
                gr%ne = ne
                gr%ndir = nd
                gr%row0 = row
                gr%params = reshape(params(ip0 + 1:ip0 + npar*ne), [npar, ne])
                allocate (gr%w0(max(nsl, 1), ne))
                gr%w0 = 0.0_wp
                if (nsl > 0) gr%w0(1:nsl, :) = reshape(w0(iw0 + 1:iw0 + nsl*ne), [nsl, ne])
                allocate (gr%x(nc, nd, ne), gr%f(nc, nd, ne), gr%jac(nc*nd, nc*nd, ne), &
                          gr%states(3, ne), stat=stat)
                if (stat /= 0) then
                    call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'hbm_setup: AFT workspaces')
                    return
                end if
                gr%states = 0.0_wp
                row = row + ne*nd
                ip0 = ip0 + npar*ne
                iw0 = iw0 + nsl*ne
            end associate
        end do
        call aft_plan_create(sys%plan, nh, nsamp, info, errmsg)
        if (info /= 0) return
        call rest_shift(sys)
        if (present(free_bodies)) then
            if (free_bodies) call hbm_free_bodies(sys, gp, gi, gx, info, errmsg)
            if (info /= 0) return
        end if
        ! contact couplings widen the band of the full formulation
        do g = 1, ng
            associate (gr => sys%cs%grp(g), gg => sys%cs%g)
                do i = 1, gr%ne
                    row = gr%row0 + (i - 1)*gr%ndir
                    k = elem_bw(gg, row + 1, row + gr%ndir, sys)
                    sys%bw = max(sys%bw, k)
                end do
            end associate
        end do
        select type (sys)
        type is (hbm_condensed)
            call cond_init(sys, nl, info, errmsg)
        type is (hbm_full)
            call full_init(sys, info, errmsg)
        end select

    contains

        !> fe0's harmonic 0 less the image in the DoFs of c0 = G^T f_rest over G's columns
        !> (T^T c0 condensed, c0 full): the contact forces are relative to rest
        !> (contact_set); nothing when no element has a force at rest.
        subroutine rest_shift(s)
            class(hbm_system), intent(inout) :: s
            real(wp), allocatable :: fr(:), c0(:), cdof(:)
            integer(ip) :: gg, e, d, r, kk, j
            allocate (c0(s%cs%g%ncol))
            c0 = 0.0_wp
            do gg = 1, size(s%cs%grp)
                associate (gr => s%cs%grp(gg), gm => s%cs%g)
                    allocate (fr(gr%ndir))
                    do e = 1, gr%ne
                        call law_rest_force(gr%law, gr%params(:, e), fr)
                        do d = 1, gr%ndir
                            if (fr(d) == 0.0_wp) cycle
                            r = gr%row0 + (e - 1)*gr%ndir + d
                            do kk = gm%p(r), gm%p(r + 1) - 1
                                c0(gm%i(kk)) = c0(gm%i(kk)) + gm%x(kk)*fr(d)
                            end do
                        end do
                    end do
                    deallocate (fr)
                end associate
            end do
            if (all(c0 == 0.0_wp)) return
            s%cs%c0 = c0
            select type (s)
            type is (hbm_condensed)
                allocate (cdof(s%ndof))
                cdof = 0.0_wp
                do j = 1, s%t%nrow
                    do kk = s%t%p(j), s%t%p(j + 1) - 1
                        cdof(s%t%i(kk)) = cdof(s%t%i(kk)) + s%t%x(kk)*c0(j)
                    end do
                end do
                s%fe0(:, 1) = s%fe0(:, 1) - cdof
            class default
                s%fe0(:, 1) = s%fe0(:, 1) - c0
            end select
        end subroutine rest_shift

        pure function pattern_bw(a) result(bw)
            type(csr_matrix), intent(in) :: a
            integer(ip) :: bw, ii, kk
            bw = 0
            do ii = 1, a%nrow
                do kk = a%p(ii), a%p(ii + 1) - 1
                    bw = max(bw, abs(sys%iperm(ii) - sys%iperm(a%i(kk))))
                end do
            end do
        end function pattern_bw

        !> Spread, under perm, of the full DoFs an element's rows touch (condensed: G's
        !> columns are nl entries, or with contact coordinates rows of T = G, whose own
        !> columns are the DoFs).
        function elem_bw(gg, r1, r2, s) result(bw)
            type(csr_matrix), intent(in) :: gg
            integer(ip), intent(in) :: r1, r2
            class(hbm_system), intent(in) :: s
            integer(ip) :: bw, lo, hi, rr, kk, col, kt
            lo = huge(lo)
            hi = -huge(hi)
            do rr = r1, r2
                do kk = gg%p(rr), gg%p(rr + 1) - 1
                    col = gg%i(kk)
                    select type (s)
                    type is (hbm_condensed)
                        if (s%tcontact) then
                            do kt = s%t%p(col), s%t%p(col + 1) - 1
                                lo = min(lo, s%iperm(s%t%i(kt)))
                                hi = max(hi, s%iperm(s%t%i(kt)))
                            end do
                            cycle
                        end if
                        col = nl(col)
                    end select
                    lo = min(lo, s%iperm(col))
                    hi = max(hi, s%iperm(col))
                end do
            end do
            bw = max(hi - lo, 0)
        end function elem_bw
    end procedure hbm_setup

    module procedure hbm_run
        type(cont_options) :: o1
        real(wp), allocatable :: zero(:), yb(:, :), lb(:), tb(:, :), t0(:), tj(:)
        real(wp) :: orient
        integer(ip) :: it, n1, maxpts, ib(1)
        logical :: have_fact
        info = FRIROM_OK
        npts = 0
        finished = .false.
        maxpts = size(lams)
        if (size(y) /= sys%n .or. size(t) /= sys%n + 1 .or. size(ys, 1) /= sys%n .or. &
            size(ys, 2) /= maxpts .or. size(tans, 1) /= sys%n + 1 .or. &
            size(xo, 1) /= size(sys%outdofs) .or. size(xo, 2) /= sys%nc .or. maxpts < 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'hbm_run: array sizes')
            return
        end if
        allocate (zero(sys%n), yb(sys%n, 1), lb(1), tb(sys%n + 1, 1), t0(sys%n + 1), &
                  tj(sys%n + 1))
        zero = 0.0_wp
        o1 = opts
        o1%max_points = 1
        if (start_mode /= HBM_START_RESUME) then
            have_fact = .false.
            call newton_correct(sys, y, lam, y, lam, zero, 1.0_wp, opts, it, info, errmsg, &
                                have_fact)
            if (info /= 0) return
            call sys%accept(y, lam, info, errmsg)
            if (info /= 0) return
            t0 = 0.0_wp
            ! the curve's orientation (cont_tangent), kept by every point after
            orient = 0.0_wp
            call cont_tangent(sys, y, lam, opts, t0, sign(1.0_wp, opts%lam_end - lam), t, &
                              info, errmsg, orient)
            if (info /= 0) return
            tj = t
            call store(it)
            if (info /= 0) return
            if (start_mode == HBM_START_SOLVE_ONLY) then
                finished = .true.
                return
            end if
        end if
        if (start_mode == HBM_START_RESUME) then
            ! J at the resumed point and its tangent tj, as the run that made the point
            ! holds them (cont_tangent left them there): the first corrector's chord steps
            ! and the corner rules, and so the path, do not depend on where calls begin
            ! (the orientation too: tj along t, as the run that made the point had it)
            orient = 0.0_wp
            call cont_tangent(sys, y, lam, o1, t, 1.0_wp, tj, info, errmsg, orient)
            if (info /= 0) return
        end if
        have_fact = .true.
        do while (npts < maxpts)
            if (orient /= 0.0_wp .and. sys%orient) then
                call cont_run(sys, y, lam, t, ds, lam_lo, o1, yb, lb, tb, ib, n1, finished, &
                              info, errmsg, have_fact, tj, orient)
            else
                call cont_run(sys, y, lam, t, ds, lam_lo, o1, yb, lb, tb, ib, n1, finished, &
                              info, errmsg, have_fact, tj)
            end if
            if (n1 == 1) then
                it = info
                call rescale()
                call store(ib(1))
                if (it /= 0) info = it
            end if
            if (info /= 0 .or. finished) return
        end do

    contains

        !> The arc length measures the unknowns against the largest solution so far
        !> (o1%yscale, grown to |y| once |y| exceeds twice it; t follows into the new
        !> scaling): near a resonance 100x above the first point, steps would otherwise
        !> crawl in the parameter, and at ds_min the chord between points would be corrector
        !> noise. After every point, so that the path does not depend on how often the
        !> caller takes the points (yscales).
        subroutine rescale()
            real(wp) :: ny
            ny = norm2(y)
            if (.not. (ny > 2.0_wp*o1%yscale)) return
            t(1:sys%n) = t(1:sys%n)*(o1%yscale/ny)
            t = t/norm2(t)
            tj(1:sys%n) = tj(1:sys%n)*(o1%yscale/ny)
            tj = tj/norm2(tj)
            o1%yscale = ny
        end subroutine rescale

        subroutine store(itn)
            integer(ip), intent(in) :: itn
            integer(ip) :: g, e0
            real(wp) :: th
            complex(wp), allocatable :: ex(:)
            npts = npts + 1
            ys(:, npts) = y
            lams(npts) = lam
            tans(:, npts) = t
            iters(npts) = itn
            if (present(yscales)) yscales(npts) = o1%yscale
            if (present(sliders)) call hbm_sliders(sys, sliders(:, npts))
            call sys%outputs(y, lam, xo(:, :, npts), info, errmsg)
            if (info /= 0) return
            if (present(leak)) then
                ! the contact forces of outputs' evaluation at y
                leak(npts) = 0.0_wp
                select type (sys)
                type is (hbm_condensed)
                    leak(npts) = cond_leak(sys)
                end select
            end if
            if (present(hill_re)) then
                allocate (ex(2*sys%ndof))
                th = wtime()
                call hbm_hill(sys, y, lam, ex, hill_re(npts), info, errmsg)
                sys%timers(T_HILL) = sys%timers(T_HILL) + wtime() - th
                if (info /= 0) return
            end if
            e0 = 0
            do g = 1, size(sys%cs%grp)
                states(:, e0 + 1:e0 + sys%cs%grp(g)%ne, npts) = sys%cs%grp(g)%states
                e0 = e0 + sys%cs%grp(g)%ne
            end do
        end subroutine store
    end procedure hbm_run

    module procedure wtime
        integer(kind=8) :: cnt, rate
        call system_clock(cnt, rate)
        t = real(cnt, wp)/real(rate, wp)
    end procedure wtime

    module procedure freq_load
        if (sys%mode == HBM_FREQUENCY) then
            w = lam
            s = 0.0_wp
        else
            w = sys%omega_fix
            s = lam
        end if
    end procedure freq_load
end submodule frirom_hbm_run
