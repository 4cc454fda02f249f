!> A whole forced-response solve from plain arrays, for legacy Fortran programs (this
!> module, `use frirom_solve`) and for C (frirom_capi's frirom_frf, declared in frirom.h).
!>
!> In: the model's K, M (and C) as coordinate triplets, linear damping (a matrix, Rayleigh
!> alpha M + beta K, modal ratios of the lowest modes, or their sum), contact groups (law,
!> elements, directions; the rows of G as triplets; parameters), the harmonic excitation,
!> the solver settings (frf_settings) and a frequency range. Out (frf_result): the
!> frequencies, the output DoFs' harmonics and peak amplitudes, the unknowns, the contact
!> states per point, whether the range was covered, a status code and its message.
!>
!> The continuation follows frirom.solver.frf step for step: a first solve at the start
!> frequency with a purely relative update test, arc length scaled by the largest solution
!> so far (rescaled after every point, in hbm_run), the run complete only when it reaches
!> the end frequency. Receptances are factorised per harmonic (Python's receptances =
!> 'factorization'); condensed unknowns are the contact coordinates G x when they are
!> fewer than the contact DoFs (Python's coordinates = 'auto').
module frirom_solve
    use, intrinsic :: iso_c_binding, only: c_int, c_double
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_LAPACK, &
                             FRIROM_ERR_ALLOC, set_status
    use frirom_lapack, only: dsygv
    use frirom_banded, only: rcm_order
    use frirom_newton, only: cont_options, cont_options_from, YSCALE_RELATIVE, N_RCONT, &
                             N_ICONT, RCONT_TOL_R, RCONT_TOL_X, RCONT_TOL_STALL, RCONT_YSCALE, &
                             RCONT_LSCALE, RCONT_DS, RCONT_DS_MIN, RCONT_DS_MAX, &
                             RCONT_LAM_END, RCONT_LAM_LO, ICONT_MAX_ITER, ICONT_REUSE_JAC
    use frirom_hbm, only: hbm_system, hbm_condensed, hbm_full, hbm_setup, hbm_run, &
                          HBM_FREQUENCY, HBM_START_CONTINUE, HBM_START_RESUME, &
                          HBM_START_SOLVE_ONLY
    implicit none
    private
    public :: frf_settings, frf_result, frf_solve, frf_default_samples, peak_amplitude
    public :: FRF_CONDENSED, FRF_BANDED

    !> frf_settings%formulation: unknowns are the contact DoFs' harmonics (Eq. 5-9) or
    !> all DoFs' harmonics (banded LU in RCM order).
    integer(ip), parameter :: FRF_CONDENSED = 1, FRF_BANDED = 2

    !> Solver settings (struct frirom_settings in frirom.h); the defaults are those of
    !> frirom.solver.SolverOptions. Steps are dimensionless (unknowns / |first point|,
    !> frequency / range).
    type, bind(c) :: frf_settings
        integer(c_int) :: harmonics = 3        !! H: harmonics 0..H
        integer(c_int) :: samples = 0          !! AFT samples per period; 0: the default
        integer(c_int) :: formulation = FRF_CONDENSED
        integer(c_int) :: max_points = 2000    !! points of the curve at most
        integer(c_int) :: max_iter = 25        !! Newton iterations per corrector
        integer(c_int) :: batch = 10           !! points per hbm_run call
        integer(c_int) :: reuse_jacobian = 1   !! 1: keep a factorisation while it contracts
        integer(c_int) :: history = 1          !! 1: carry the contact sliders along the curve
        real(c_double) :: tol_residual = 1.0e-8_c_double
        real(c_double) :: tol_update = 1.0e-8_c_double
        real(c_double) :: tol_stall = 0.0_c_double
        real(c_double) :: ds = 0.02_c_double   !! first arc-length step
        real(c_double) :: ds_min = 1.0e-6_c_double
        real(c_double) :: ds_max = 0.1_c_double
    end type frf_settings

    !> The forced response: npts points, in the order of the continuation.
    type :: frf_result
        integer(ip) :: npts = 0                 !! points computed
        integer(ip) :: ny = 0                   !! unknowns per point
        logical :: complete = .false.           !! the curve reached omega_end
        integer(ip) :: info = FRIROM_OK         !! status of the last solve (0: none failed)
        character(len=512) :: message = ''      !! why the run stopped early, or ''
        real(wp), allocatable :: omega(:)       !! (npts) rad/s
        real(wp), allocatable :: xo(:, :, :)    !! (nout, 2H+1, npts) output harmonics
        real(wp), allocatable :: amp(:, :)      !! (nout, npts) max over a period of |x(t)|
        real(wp), allocatable :: y(:, :)        !! (ny, npts) unknowns
        real(wp), allocatable :: states(:, :, :)  !! (3, n_elements, npts) stick/slip/open
        integer(ip), allocatable :: iters(:)    !! (npts) Newton iterations
    end type frf_result

contains

    !> AFT samples per period by default for H harmonics (also frirom.harmonics.default_samples):
    !> 512, or 16 per period of harmonic H rounded up to a power of two when more.
    pure function frf_default_samples(nh) result(ns)
        integer(ip), intent(in) :: nh
        integer(ip) :: ns
        ns = 512
        do while (ns < 16*(2*nh + 1))
            ns = 2*ns
        end do
    end function frf_default_samples

    !> max over one period of |x(t)|, x(t) = a0 + sum_h a_h cos(h t) + b_h sin(h t): the
    !> largest of 16(2H+1) samples and of the sampled local maxima polished by Newton on
    !> x'(t) = 0 (every candidate a real time: never above the true maximum).
    pure function peak_amplitude(x) result(amax)
        real(wp), intent(in) :: x(:)          !! (2H+1) [a0, a1, b1, ..., aH, bH]
        real(wp) :: amax
        real(wp), parameter :: twopi = 2.0_wp*acos(-1.0_wp)
        real(wp) :: v(16*size(x)), t, d1, d2, step
        integer(ip) :: ns, k, it
        ns = size(v)
        do k = 1, ns
            v(k) = abs(trig(twopi*(k - 1)/ns, 0_ip))
        end do
        amax = maxval(v)
        do k = 1, ns
            if (v(k) < v(modulo(k - 2, ns) + 1) .or. v(k) < v(modulo(k, ns) + 1)) cycle
            t = twopi*(k - 1)/ns
            do it = 1, 20
                d1 = trig(t, 1_ip)
                d2 = trig(t, 2_ip)
                if (d2*sign(1.0_wp, trig(t, 0_ip)) >= 0.0_wp) exit   ! not a maximum of |x|
                step = d1/d2
                if (abs(step) > twopi/ns) exit
                t = t - step
                if (abs(step) <= 1.0e-15_wp*twopi) exit
            end do
            amax = max(amax, abs(trig(t, 0_ip)))
        end do

    contains

        !> The m-th time derivative of x at t (m = 0, 1, 2).
        pure function trig(tt, m) result(s)
            real(wp), intent(in) :: tt
            integer(ip), intent(in) :: m
            real(wp) :: s, c, sn
            integer(ip) :: h
            s = merge(x(1), 0.0_wp, m == 0)
            do h = 1, (size(x) - 1)/2
                c = cos(h*tt)
                sn = sin(h*tt)
                select case (m)
                case (0)
                    s = s + x(2*h)*c + x(2*h + 1)*sn
                case (1)
                    s = s + h*(x(2*h + 1)*c - x(2*h)*sn)
                case default
                    s = s - h*h*(x(2*h)*c + x(2*h + 1)*sn)
                end select
            end do
        end function trig
    end function peak_amplitude

    !> Coordinate triplets (1-based, duplicates summed) of an nrow x ncol matrix to CSR with
    !> sorted columns; an empty matrix keeps one explicit zero (hbm_setup needs an entry).
    subroutine coo_csr(nrow, ncol, r, c, v, name, p, ci, x, info, errmsg)
        integer(ip), intent(in) :: nrow, ncol, r(:), c(:)
        real(wp), intent(in) :: v(:)
        character(len=*), intent(in) :: name
        integer(ip), allocatable, intent(out) :: p(:), ci(:)
        real(wp), allocatable, intent(out) :: x(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: k, i, j, q, nz, at(nrow + 1)
        integer(ip), allocatable :: cs(:)
        real(wp), allocatable :: xs(:)
        real(wp) :: tx
        info = FRIROM_OK
        allocate (p(nrow + 1))
        if (size(c) /= size(r) .or. size(v) /= size(r)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': rows, columns and values '// &
                            'differ in length')
            return
        end if
        if (any(r < 1) .or. any(r > nrow) .or. any(c < 1) .or. any(c > ncol)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': an index is out of range')
            return
        end if
        if (.not. all(abs(v) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': NaN or Inf value')
            return
        end if
        ! counting sort by row, then insertion sort of each row's columns
        at = 0
        do k = 1, size(r)
            at(r(k) + 1) = at(r(k) + 1) + 1
        end do
        at(1) = 1
        do i = 1, nrow
            at(i + 1) = at(i + 1) + at(i)
        end do
        allocate (cs(size(r)), xs(size(r)))
        p = at
        do k = 1, size(r)
            cs(p(r(k))) = c(k)
            xs(p(r(k))) = v(k)
            p(r(k)) = p(r(k)) + 1
        end do
        nz = 0
        p(1) = 1
        do i = 1, nrow
            do k = at(i) + 1, at(i + 1) - 1
                q = cs(k)
                tx = xs(k)
                j = k - 1
                do while (j >= at(i))
                    if (cs(j) <= q) exit
                    cs(j + 1) = cs(j)
                    xs(j + 1) = xs(j)
                    j = j - 1
                end do
                cs(j + 1) = q
                xs(j + 1) = tx
            end do
            do k = at(i), at(i + 1) - 1      ! merge duplicates in place (nz <= k)
                if (nz >= p(i)) then
                    if (cs(nz) == cs(k)) then
                        xs(nz) = xs(nz) + xs(k)
                        cycle
                    end if
                end if
                nz = nz + 1
                cs(nz) = cs(k)
                xs(nz) = xs(k)
            end do
            p(i + 1) = nz + 1
        end do
        if (nz == 0) then
            ci = [1_ip]
            x = [0.0_wp]
        else
            ci = cs(1:nz)
            x = xs(1:nz)
        end if
    end subroutine coo_csr

    !> Dense modal damping C = M Phi diag(2 zeta_r w_r) Phi^T M of the lowest size(zeta)
    !> modes (Phi M-normalised, K Phi = M Phi w^2; frirom.reduction.damping.modal_damping).
    subroutine modal_c(n, kp, ki, kx, mp, mi, mx, zeta, cd, info, errmsg)
        integer(ip), intent(in) :: n, kp(:), ki(:), mp(:), mi(:)
        real(wp), intent(in) :: kx(:), mx(:), zeta(:)
        real(wp), intent(out) :: cd(n, n)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp), allocatable :: a(:, :), b(:, :), md(:, :), w(:), work(:), mphi(:, :)
        real(wp) :: q(1)
        integer(ip) :: nm, r
        info = FRIROM_OK
        nm = size(zeta)
        allocate (a(n, n), b(n, n), w(n))
        call dense(kp, ki, kx, a)
        call dense(mp, mi, mx, b)
        md = b
        call dsygv(1, 'V', 'U', n, a, n, b, n, w, q, -1, info)
        allocate (work(max(1, int(q(1)))))
        call dsygv(1, 'V', 'U', n, a, n, b, n, w, work, size(work), info)
        if (info /= 0) then
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'damping: eigen-solve of (K, M) '// &
                            'failed for the modal ratios; is M positive definite?')
            return
        end if
        mphi = matmul(md, a(:, 1:nm))
        do r = 1, nm
            mphi(:, r) = mphi(:, r)*sqrt(2.0_wp*zeta(r)*sqrt(max(w(r), 0.0_wp)))
        end do
        cd = matmul(mphi, transpose(mphi))
        cd = 0.5_wp*(cd + transpose(cd))

    contains

        subroutine dense(pp, ii, xx, d)
            integer(ip), intent(in) :: pp(:), ii(:)
            real(wp), intent(in) :: xx(:)
            real(wp), intent(out) :: d(:, :)
            integer(ip) :: row, kk
            d = 0.0_wp
            do row = 1, n
                do kk = pp(row), pp(row + 1) - 1
                    d(row, ii(kk)) = d(row, ii(kk)) + xx(kk)
                end do
            end do
        end subroutine dense
    end subroutine modal_c

    !> Forced response from omega_start to omega_end (rad/s, either direction) by
    !> pseudo-arc-length continuation through turning points. Indices are 1-based. The
    !> matrices list every entry (both triangles of a symmetric matrix; duplicates add).
    !> Damping: the matrix C (cr, cc, cv; may be empty) plus alpha M + beta K plus modal
    !> ratios zeta of the lowest size(zeta) modes. Contact group g (ginfo(:, g) = law code
    !> (frirom_aft LAW_*), elements, directions) owns the next ne*ndir rows of G, element by
    !> element; G(row, col) = gv from the triplets (gr, gc, gv) over all groups; params the
    !> groups' (npar, ne) parameters concatenated; w0 their initial sliders (default zero).
    !> A failure to start, or bad input, is res%info /= 0 with no point; a run that stops
    !> later keeps its points, with res%complete false and res%message saying why.
    subroutine frf_solve(n, kr, kc, kv, mr, mc, mv, cr, cc, cv, alpha, beta, zeta, ginfo, &
                         gr, gc, gv, params, fe, omega_start, omega_end, outdofs, s, res, w0)
        integer(ip), intent(in) :: n                   !! DoFs
        integer(ip), intent(in) :: kr(:), kc(:)        !! K entries' rows and columns
        real(wp), intent(in) :: kv(:)                  !! K values, N/m
        integer(ip), intent(in) :: mr(:), mc(:)
        real(wp), intent(in) :: mv(:)                  !! M values, kg
        integer(ip), intent(in) :: cr(:), cc(:)
        real(wp), intent(in) :: cv(:)                  !! C values, N s/m
        real(wp), intent(in) :: alpha, beta            !! Rayleigh: 1/s, s
        real(wp), intent(in) :: zeta(:)                !! modal damping ratios, lowest first
        integer(ip), intent(in) :: ginfo(:, :)         !! (3, ngroup) law, ne, ndir
        integer(ip), intent(in) :: gr(:), gc(:)        !! G entries' rows and columns
        real(wp), intent(in) :: gv(:)
        real(wp), intent(in) :: params(:)              !! contact parameters (law units)
        real(wp), intent(in) :: fe(:, :)               !! (n, 2H+1) excitation harmonics, N
        real(wp), intent(in) :: omega_start, omega_end !! rad/s
        integer(ip), intent(in) :: outdofs(:)          !! DoFs whose response is kept
        type(frf_settings), intent(in) :: s
        type(frf_result), intent(out) :: res
        real(wp), intent(in), optional :: w0(:)        !! initial sliders, groups concatenated
        class(hbm_system), allocatable :: sys
        integer(ip), allocatable :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:), gp(:), gi(:), &
                                    perm(:), nl(:)
        real(wp), allocatable :: kx(:), mx(:), cx(:), gx(:), cd(:, :), wsl(:)
        real(wp), allocatable :: y0(:), t0(:), ys(:, :), lams(:), tans(:, :), xo(:, :, :), &
                                 st(:, :, :), tan_last(:), yscs(:)
        integer(ip), allocatable :: itb(:)
        integer(ip) :: nh, nc, nrows, ne, info, i, j, k, nout, cap, maxpts, np, k0, start
        real(wp) :: lscale, lam_lo, yscale, lam0, ds, ysc_last, rv(N_RCONT)
        integer(ip) :: iv(N_ICONT)
        logical :: fin, pending, tcontact
        character(len=512) :: msg
        type(cont_options) :: opts

        msg = ''
        nh = s%harmonics
        nc = 2*nh + 1
        nout = size(outdofs)
        call check_input(info, msg)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        ! K, M, C as CSR (C: matrix + Rayleigh + modal)
        call coo_csr(n, n, kr, kc, kv, 'K', kp, ki, kx, info, msg)
        if (info == 0) call coo_csr(n, n, mr, mc, mv, 'M', mp, mi, mx, info, msg)
        if (info == 0) then
            allocate (cd(n, n))
            cd = 0.0_wp
            if (size(zeta) > 0) call modal_c(n, kp, ki, kx, mp, mi, mx, zeta, cd, info, msg)
        end if
        if (info == 0) then
            ! C + beta K + alpha M + the modal part, summed by coo_csr
            call coo_csr(n, n, [cr, rows_of(kp, beta), rows_of(mp, alpha), &
                                pack(spread([(i, i=1, n)], 2, n), cd /= 0.0_wp)], &
                         [cc, cols_of(kp, ki, beta), cols_of(mp, mi, alpha), &
                          pack(spread([(i, i=1, n)], 1, n), cd /= 0.0_wp)], &
                         [cv, vals_of(kp, kx, beta), vals_of(mp, mx, alpha), &
                          pack(cd, cd /= 0.0_wp)], 'C', cp, ci, cx, info, msg)
        end if
        nrows = sum(ginfo(2, :)*ginfo(3, :))
        if (info == 0) call coo_csr(nrows, n, gr, gc, gv, 'G', gp, gi, gx, info, msg)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        call rcm_pattern(info, msg)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        ! the contact DoFs: G's columns, sorted
        block
            logical :: used(n)
            used = .false.
            if (gp(nrows + 1) > 1) used(gi(1:gp(nrows + 1) - 1)) = .true.
            nl = pack([(i, i=1, n)], used)
        end block
        tcontact = s%formulation == FRF_CONDENSED .and. nrows < size(nl)
        if (s%formulation == FRF_CONDENSED) then
            allocate (hbm_condensed :: sys)
        else
            allocate (hbm_full :: sys)
        end if
        ne = sum(ginfo(2, :))
        allocate (wsl(max(size(params), 1)))    ! sliders: at most one per parameter
        wsl = 0.0_wp
        if (present(w0)) wsl(1:min(size(w0), size(wsl))) = w0(1:min(size(w0), size(wsl)))
        call hbm_setup(sys, nh, merge(s%samples, frf_default_samples(nh), s%samples > 0), n, &
                       kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe, 0.0_wp*fe, &
                       HBM_FREQUENCY, 0.0_wp, ginfo, gp, gi, gx, params, wsl, outdofs, info, &
                       msg, contact_coords=tcontact, krylov=0_ip, sparse_lu=.false.)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        res%ny = sys%n
        cap = 0                 ! the result arrays grow as points come (keep)
        allocate (res%omega(0), res%xo(nout, nc, 0), res%amp(nout, 0), res%y(sys%n, 0), &
                  res%states(3, max(ne, 1), 0), res%iters(0))
        lscale = abs(omega_end - omega_start)
        if (lscale == 0.0_wp) lscale = 1.0_wp
        lam_lo = omega_start - 0.02_wp*(omega_end - omega_start)
        ! the first point, at fixed frequency with a purely relative update test
        allocate (y0(sys%n), t0(sys%n + 1), tan_last(sys%n + 1))
        y0 = 0.0_wp
        t0 = 0.0_wp
        lam0 = omega_start
        ds = s%ds
        call run_call(HBM_START_SOLVE_ONLY, YSCALE_RELATIVE, 1_ip)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        call keep(1_ip)
        if (info /= 0) then
            call fail(info, msg)
            return
        end if
        y0 = ys(:, 1)
        yscale = norm2(y0)
        if (yscale == 0.0_wp) yscale = 1.0_wp
        pending = .true.
        start = HBM_START_CONTINUE
        res%complete = .false.
        fin = .false.
        do while (res%npts < s%max_points)
            maxpts = min(s%batch, s%max_points - res%npts) + merge(1, 0, pending)
            call run_call(start, yscale, maxpts)
            k0 = 1
            if (pending .and. np > 0) k0 = 2     ! the first point again: its tangent only
            if (pending .and. np > 0) tan_last = tans(:, 1)
            if (pending .and. np > 0) ysc_last = yscs(1)
            pending = .false.
            do k = k0, np
                call keep(k)
            end do
            if (info /= 0) then
                res%info = info
                res%message = msg
                exit
            end if
            ! continue from the last point, in the arc-length scale of its tangent
            j = res%npts
            y0 = res%y(:, j)
            lam0 = res%omega(j)
            t0 = tan_last
            yscale = ysc_last
            start = HBM_START_RESUME
            if (fin) then
                res%complete = .true.
                exit
            end if
        end do
        if (info == 0 .and. .not. fin) write (res%message, '(a,i0,a)') &
            'stopped after max_points = ', s%max_points, ' points'
        if (res%complete .and. res%omega(res%npts) /= omega_end) then
            res%complete = .false.
            write (res%message, '(a,es14.7,a)') 'the solution curve turned back and left '// &
                'the range through omega = ', res%omega(res%npts), ' rad/s'
        end if
        res%omega = res%omega(1:res%npts)
        res%xo = res%xo(:, :, 1:res%npts)
        res%amp = res%amp(:, 1:res%npts)
        res%y = res%y(:, 1:res%npts)
        res%states = res%states(:, :, 1:res%npts)
        res%iters = res%iters(1:res%npts)

    contains

        subroutine check_input(st, m)
            integer(ip), intent(out) :: st
            character(len=*), intent(inout) :: m
            st = FRIROM_OK
            if (n < 1 .or. nh < 0 .or. nh > 200) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: need n >= 1 and '// &
                                'settings%harmonics in 0..200')
            else if (size(fe, 1) /= n .or. size(fe, 2) /= nc) then
                call set_status(st, FRIROM_ERR_SIZE, m, 'frf_solve: fe must be (n, 2H+1)')
            else if (size(ginfo, 1) /= 3) then
                call set_status(st, FRIROM_ERR_SIZE, m, 'frf_solve: ginfo must be (3, ngroup)')
            else if (any(ginfo(2:3, :) < 1)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: ginfo: every group needs '// &
                                '>= 1 element and direction')
            else if (nout < 1 .or. any(outdofs < 1) .or. any(outdofs > n)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: outdofs must name '// &
                                'DoFs 1..n (at least one)')
            else if (s%formulation /= FRF_CONDENSED .and. s%formulation /= FRF_BANDED) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: settings%formulation '// &
                                'must be FRF_CONDENSED (1) or FRF_BANDED (2)')
            else if (s%max_points < 1 .or. s%max_iter < 1 .or. s%batch < 1 .or. &
                     (s%samples /= 0 .and. s%samples < nc)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: settings max_points, '// &
                                'max_iter, batch must be >= 1 and samples 0 or >= 2H+1')
            else if (.not. (s%tol_residual > 0 .and. s%tol_update > 0 .and. s%ds > 0 .and. &
                            s%ds_min > 0 .and. s%ds_min <= s%ds_max .and. &
                            s%tol_stall >= 0)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: settings tol_residual, '// &
                                'tol_update, ds, ds_min must be > 0, ds_min <= ds_max')
            else if (.not. (alpha >= 0 .and. beta >= 0 .and. all(zeta >= 0) .and. &
                            all(zeta < 1) .and. size(zeta) <= n)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: damping alpha, beta '// &
                                'must be >= 0 and zeta at most n ratios in [0, 1)')
            else if (.not. (abs(omega_start) <= huge(1.0_wp) .and. &
                            abs(omega_end) <= huge(1.0_wp) .and. all(abs(fe) <= huge(1.0_wp)))) &
                then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf_solve: omega or fe is NaN or Inf')
            else if (s%formulation == FRF_CONDENSED .and. size(gr) == 0) then
                call set_status(st, FRIROM_ERR_PARAM, m, "frf_solve: the condensed "// &
                                "formulation needs contacts (use FRF_BANDED)")
            end if
        end subroutine check_input

        subroutine fail(st, m)
            integer(ip), intent(in) :: st
            character(len=*), intent(in) :: m
            res%info = st
            res%message = m
            res%npts = 0
            allocate (res%omega(0), res%xo(nout, nc, 0), res%amp(nout, 0), res%y(res%ny, 0), &
                      res%states(3, 0, 0), res%iters(0))
        end subroutine fail

        !> Rows, columns and f times the values of a CSR matrix's entries (none if f = 0).
        pure function rows_of(p, f) result(r)
            integer(ip), intent(in) :: p(:)
            real(wp), intent(in) :: f
            integer(ip), allocatable :: r(:)
            integer(ip) :: row
            if (f == 0.0_wp) then
                allocate (r(0))
            else
                r = [(spread(row, 1, p(row + 1) - p(row)), row=1, size(p) - 1)]
            end if
        end function rows_of

        pure function cols_of(p, ix, f) result(c)
            integer(ip), intent(in) :: p(:), ix(:)
            real(wp), intent(in) :: f
            integer(ip), allocatable :: c(:)
            c = ix(1:merge(p(size(p)) - 1, 0, f /= 0.0_wp))
        end function cols_of

        pure function vals_of(p, x, f) result(v)
            integer(ip), intent(in) :: p(:)
            real(wp), intent(in) :: x(:), f
            real(wp), allocatable :: v(:)
            v = f*x(1:merge(p(size(p)) - 1, 0, f /= 0.0_wp))
        end function vals_of

        !> perm: RCM order of the pattern of K + M + C + G^T G + I (as frirom._pack).
        subroutine rcm_pattern(st, m)
            integer(ip), intent(out) :: st
            character(len=*), intent(inout) :: m
            integer(ip), allocatable :: rr(:), cc2(:), ap(:), ai(:)
            real(wp), allocatable :: ax(:)
            integer(ip) :: row, a, b, q
            q = 0
            do row = 1, nrows
                q = q + (gp(row + 1) - gp(row))**2
            end do
            allocate (rr(q), cc2(q))
            q = 0
            do row = 1, nrows                    ! G^T G couples the columns of each row
                do a = gp(row), gp(row + 1) - 1
                    do b = gp(row), gp(row + 1) - 1
                        q = q + 1
                        rr(q) = gi(a)
                        cc2(q) = gi(b)
                    end do
                end do
            end do
            rr = [rr, [(row, row=1, n)], rows_of(kp, 1.0_wp), rows_of(mp, 1.0_wp), &
                  rows_of(cp, 1.0_wp)]
            cc2 = [cc2, [(row, row=1, n)], cols_of(kp, ki, 1.0_wp), cols_of(mp, mi, 1.0_wp), &
                   cols_of(cp, ci, 1.0_wp)]
            ! symmetric: both (r, c) and (c, r)
            call coo_csr(n, n, [rr, cc2], [cc2, rr], [(1.0_wp, row=1, 2*size(rr))], &
                         'pattern', ap, ai, ax, st, m)
            if (st /= 0) return
            allocate (perm(n))
            call rcm_order(ap, ai, perm, st, m)
        end subroutine rcm_pattern
        !> One hbm_run call of at most mx points from (y0, lam0, t0) with step ds.
        subroutine run_call(mode, ysc, mx)
            integer(ip), intent(in) :: mode, mx
            real(wp), intent(in) :: ysc
            real(wp) :: y(sys%n), t(sys%n + 1), lam, dsl
            rv(RCONT_TOL_R) = s%tol_residual
            rv(RCONT_TOL_X) = s%tol_update
            rv(RCONT_TOL_STALL) = s%tol_stall
            rv(RCONT_YSCALE) = ysc
            rv(RCONT_LSCALE) = lscale
            rv(RCONT_DS) = ds
            rv(RCONT_DS_MIN) = s%ds_min
            rv(RCONT_DS_MAX) = s%ds_max
            rv(RCONT_LAM_END) = omega_end
            rv(RCONT_LAM_LO) = lam_lo
            iv(ICONT_MAX_ITER) = s%max_iter
            iv(ICONT_REUSE_JAC) = s%reuse_jacobian
            opts = cont_options_from(rv, iv)
            opts%max_points = mx
            if (allocated(ys)) deallocate (ys, lams, tans, itb, xo, st, yscs)
            allocate (ys(sys%n, mx), lams(mx), tans(sys%n + 1, mx), itb(mx), &
                      xo(nout, nc, mx), st(3, max(ne, 1), mx), yscs(mx))
            sys%carry = s%history /= 0
            y = y0
            t = t0
            lam = lam0
            dsl = ds
            call hbm_run(sys, mode, y, lam, t, dsl, lam_lo, opts, ys, lams, tans, itb, xo, st, &
                         np, fin, info, msg, yscales=yscs)
            ds = dsl
        end subroutine run_call

        !> Keep point k of the last call (info = FRIROM_ERR_ALLOC if there is no room).
        subroutine keep(kk)
            integer(ip), intent(in) :: kk
            integer(ip) :: o
            if (res%npts == cap) then
                if (.not. grown(min(max(2*cap, 16_ip), int(s%max_points, ip)))) return
            end if
            res%npts = res%npts + 1
            j = res%npts
            res%omega(j) = lams(kk)
            res%xo(:, :, j) = xo(:, :, kk)
            do o = 1, nout
                res%amp(o, j) = peak_amplitude(xo(o, :, kk))
            end do
            res%y(:, j) = ys(:, kk)
            res%states(:, :, j) = st(:, :, kk)
            res%iters(j) = itb(kk)
            tan_last = tans(:, kk)
            ysc_last = yscs(kk)
        end subroutine keep
        !> Room for nn points in the result arrays (the npts kept are copied); false, with
        !> info = FRIROM_ERR_ALLOC and the message, when memory runs out.
        logical function grown(nn)
            integer(ip), intent(in) :: nn
            real(wp), allocatable :: a1(:), a2(:, :), a3(:, :, :), b2(:, :), b3(:, :, :)
            integer(ip), allocatable :: i1(:)
            integer(ip) :: m, stat
            m = res%npts
            allocate (a1(nn), a2(nout, nn), a3(nout, nc, nn), b2(res%ny, nn), &
                      b3(size(res%states, 1), size(res%states, 2), nn), i1(nn), stat=stat)
            grown = stat == 0
            if (.not. grown) then
                call set_status(info, FRIROM_ERR_ALLOC, msg, 'frf_solve: no memory for '// &
                                'more points')
                return
            end if
            a1(1:m) = res%omega(1:m)
            a2(:, 1:m) = res%amp(:, 1:m)
            a3(:, :, 1:m) = res%xo(:, :, 1:m)
            b2(:, 1:m) = res%y(:, 1:m)
            b3(:, :, 1:m) = res%states(:, :, 1:m)
            i1(1:m) = res%iters(1:m)
            call move_alloc(a1, res%omega)
            call move_alloc(a2, res%amp)
            call move_alloc(a3, res%xo)
            call move_alloc(b2, res%y)
            call move_alloc(b3, res%states)
            call move_alloc(i1, res%iters)
            cap = nn
        end function grown
    end subroutine frf_solve
end module frirom_solve
