!> The whole forced response from plain arrays, for legacy Fortran programs (this module,
!> `use frirom_solve`) and for C (frirom_capi, declared in frirom.h): frf_open opens a run
!> of frirom_run (the one continuation driver) on a model given as coordinate triplets,
!> and frf_solve is a convenience loop over that run (open, start, advance until it
!> stops, close) that collects its points.
!>
!> In: the model's K, M (and C) as coordinate triplets, linear damping (a matrix, Rayleigh
!> alpha M + beta K, modal ratios of the lowest modes, or their sum), contact groups (law,
!> elements, directions; the rows of G as triplets; parameters), the harmonic excitation,
!> the solver settings (frf_settings, frirom_run's run_settings) and a frequency range.
!> Out (frf_result): the frequencies, the output DoFs' harmonics and peak amplitudes, the
!> unknowns, the contact states per point, whether the range was covered, a status code
!> and its message. Condensed unknowns are the contact coordinates G x when they are
!> fewer than the contact DoFs (Python's coordinates = 'auto'); receptances are factorised
!> per harmonic (banded LU, or MUMPS with sparse), or by modes after frirom_run's
!> run_set_modes on an opened run.
module frirom_solve
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, FRIROM_ERR_ALLOC, &
                             set_status
    use frirom_peak, only: peak_exact => peak_amplitude
    use frirom_damping, only: modal_damping
    use frirom_banded, only: rcm_order
    use frirom_csr, only: coo_csr
    use frirom_run, only: run_t, run_points, frf_settings => run_settings, run_open, &
                          run_start, run_advance, run_close, run_default_samples, &
                          RUN_CONDENSED, RUN_BANDED, RUN_FREQUENCY, RUN_START_COLD, RUN_GOING, &
                          RUN_DONE, RUN_FAILED, run_contact_coords, COORD_AUTO
    implicit none
    private
    public :: frf_settings, frf_result, frf_open, frf_solve, frf_default_samples, &
              peak_amplitude
    public :: FRF_CONDENSED, FRF_BANDED

    !> frf_settings%formulation: unknowns are the contact DoFs' harmonics (Eq. 5-9) or
    !> all DoFs' harmonics (banded LU in RCM order).
    integer(ip), parameter :: FRF_CONDENSED = RUN_CONDENSED, FRF_BANDED = RUN_BANDED

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

    !> AFT samples per period by default for H harmonics (frirom_run run_default_samples).
    pure function frf_default_samples(nh) result(ns)
        integer(ip), intent(in) :: nh
        integer(ip) :: ns
        ns = run_default_samples(nh)
    end function frf_default_samples

    !> max over one period of |x(t)|, x(t) = a0 + sum_h a_h cos(h t) + b_h sin(h t), for
    !> callers that want it as a function (frirom_peak peak_amplitude, the one algorithm:
    !> exact, from the roots of x'(t)); NaN for non-finite coefficients.
    pure function peak_amplitude(x) result(amax)
        real(wp), intent(in) :: x(:)          !! (2H+1) [a0, a1, b1, ..., aH, bH]
        real(wp) :: amax
        real(wp) :: t
        integer(ip) :: st
        call peak_exact(x, amax, t, st)
    end function peak_amplitude

    !> Dense modal damping C = M Phi diag(2 zeta_r w_r) Phi^T M of the lowest size(zeta)
    !> modes (frirom_damping modal_damping, the kernel frirom.reduction.damping calls too).
    subroutine modal_c(n, kp, ki, kx, mp, mi, mx, zeta, cd, info, errmsg)
        integer(ip), intent(in) :: n, kp(:), ki(:), mp(:), mi(:)
        real(wp), intent(in) :: kx(:), mx(:), zeta(:)
        real(wp), intent(out) :: cd(n, n)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        real(wp) :: kd(n, n), md(n, n), omega(size(zeta))
        call dense(kp, ki, kx, kd)
        call dense(mp, mi, mx, md)
        call modal_damping(kd, md, zeta, cd, omega, info, errmsg)

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

    !> Open a run (frirom_run) on a model given as triplets. Indices are 1-based. The
    !> matrices list every entry (both triangles of a symmetric matrix; duplicates add).
    !> Damping: the matrix C (cr, cc, cv; may be empty) plus alpha M + beta K plus modal
    !> ratios zeta of the lowest size(zeta) modes. Contact group g (ginfo(:, g) = law code
    !> (frirom_aft LAW_*), elements, directions) owns the next ne*ndir rows of G, element by
    !> element; G(row, col) = gv from the triplets (gr, gc, gv) over all groups; params the
    !> groups' (npar, ne) parameters concatenated; w0 their initial sliders (default zero).
    !> fe (n, 2H+1) the excitation; outdofs the DoFs whose response is kept; sparse:
    !> condensed receptances by sparse LU (MUMPS); krylov: GMRES solves preconditioned by an
    !> older LU. Then run_start, run_advance, ... on run; run_close frees it.
    subroutine frf_open(run, n, kr, kc, kv, mr, mc, mv, cr, cc, cv, alpha, beta, zeta, &
                        ginfo, gr, gc, gv, params, fe, outdofs, s, info, msg, w0, sparse, &
                        krylov)
        type(run_t), intent(inout) :: run
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
        integer(ip), intent(in) :: outdofs(:)          !! DoFs whose response is kept
        type(frf_settings), intent(in) :: s
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: msg
        real(wp), intent(in), optional :: w0(:)        !! initial sliders, groups concatenated
        logical, intent(in), optional :: sparse
        logical, intent(in), optional :: krylov
        integer(ip), allocatable :: kp(:), ki(:), mp(:), mi(:), cp(:), ci(:), gp(:), gi(:), &
                                    perm(:), nl(:)
        real(wp), allocatable :: kx(:), mx(:), cx(:), gx(:), cd(:, :), wsl(:)
        integer(ip) :: nh, nc, nrows, i, nout
        logical :: tcontact, sp
        info = FRIROM_OK
        nh = s%harmonics
        nc = 2*nh + 1
        nout = size(outdofs)
        call check_input(info, msg)
        if (info /= 0) return
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
        if (info == 0) call rcm_pattern(info, msg)
        if (info /= 0) return
        ! the contact DoFs: G's columns, sorted
        block
            logical :: used(n)
            used = .false.
            if (gp(nrows + 1) > 1) used(gi(1:gp(nrows + 1) - 1)) = .true.
            nl = pack([(i, i=1, n)], used)
        end block
        if (size(nl) == 0) nl = [1_ip]
        tcontact = s%formulation == FRF_CONDENSED .and. &
                   run_contact_coords(COORD_AUTO, nrows, size(nl, kind=ip), s%stability /= 0, &
                                      .false.)
        allocate (wsl(max(size(params), 1)))    ! sliders: at most one per parameter
        wsl = 0.0_wp
        if (present(w0)) wsl(1:min(size(w0), size(wsl))) = w0(1:min(size(w0), size(wsl)))
        sp = .false.
        if (present(sparse)) sp = sparse
        i = 0
        if (present(krylov)) i = merge(1_ip, 0_ip, krylov)
        call run_open(run, s, int(s%formulation, ip), RUN_FREQUENCY, int(s%samples, ip), n, &
                      kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe, 0.0_wp*fe, 0.0_wp, &
                      ginfo, gp, gi, gx, params, wsl, outdofs, tcontact, i, sp, info, msg)

    contains

        subroutine check_input(st, m)
            integer(ip), intent(out) :: st
            character(len=*), intent(inout) :: m
            st = FRIROM_OK
            if (n < 1 .or. nh < 0 .or. nh > 200) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf: n: expected >= 1 DoF, '// &
                                'settings.harmonics in 0..200')
            else if (size(fe, 1) /= n .or. size(fe, 2) /= nc) then
                call set_status(st, FRIROM_ERR_SIZE, m, 'frf: fe: expected (n, 2H+1)')
            else if (size(ginfo, 1) /= 3) then
                call set_status(st, FRIROM_ERR_SIZE, m, 'frf: ginfo: expected (3, ngroup)')
            else if (any(ginfo(2:3, :) < 1)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf: ginfo: every group needs '// &
                                '>= 1 element and direction')
            else if (nout < 1 .or. any(outdofs < 1) .or. any(outdofs > n)) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf: outdofs: expected DoFs '// &
                                '1..n (at least one)')
            else if (.not. (alpha >= 0 .and. beta >= 0 .and. all(zeta >= 0) .and. &
                            all(zeta < 1) .and. size(zeta) <= n .and. &
                            alpha <= huge(1.0_wp) .and. beta <= huge(1.0_wp))) then
                call set_status(st, FRIROM_ERR_PARAM, m, 'frf: damping: alpha, beta '// &
                                'finite and >= 0, zeta at most n ratios in [0, 1) expected')
            else if (s%formulation == FRF_CONDENSED .and. size(gr) == 0) then
                call set_status(st, FRIROM_ERR_PARAM, m, "frf: the condensed "// &
                                "formulation needs contacts (use FRF_BANDED)")
            end if
        end subroutine check_input

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
    end subroutine frf_open

    !> Forced response from omega_start to omega_end (rad/s, either direction) by
    !> pseudo-arc-length continuation through turning points: frf_open, then the run's
    !> points settings%batch at a time until it stops. Arguments as frf_open's. A failure
    !> to start, or bad input, is res%info /= 0 with no point; a run that stops later
    !> keeps its points, with res%complete false and res%message saying why.
    subroutine frf_solve(n, kr, kc, kv, mr, mc, mv, cr, cc, cv, alpha, beta, zeta, ginfo, &
                         gr, gc, gv, params, fe, omega_start, omega_end, outdofs, s, res, w0)
        integer(ip), intent(in) :: n, kr(:), kc(:), mr(:), mc(:), cr(:), cc(:)
        real(wp), intent(in) :: kv(:), mv(:), cv(:), alpha, beta, zeta(:)
        integer(ip), intent(in) :: ginfo(:, :), gr(:), gc(:)
        real(wp), intent(in) :: gv(:), params(:), fe(:, :)
        real(wp), intent(in) :: omega_start, omega_end !! rad/s
        integer(ip), intent(in) :: outdofs(:)
        type(frf_settings), intent(in) :: s
        type(frf_result), intent(out) :: res
        real(wp), intent(in), optional :: w0(:)
        type(run_t) :: run
        type(run_points) :: pts
        integer(ip) :: info, nout, nc, k, cap
        character(len=512) :: msg
        msg = ''
        nout = size(outdofs)
        nc = 2*s%harmonics + 1
        allocate (res%omega(0), res%xo(nout, max(nc, 1), 0), res%amp(nout, 0), &
                  res%y(0, 0), res%states(3, 0, 0), res%iters(0))
        call frf_open(run, n, kr, kc, kv, mr, mc, mv, cr, cc, cv, alpha, beta, zeta, ginfo, &
                      gr, gc, gv, params, fe, outdofs, s, info, msg, w0)
        if (info == 0) then
            res%ny = run%ny
            deallocate (res%y, res%states)
            allocate (res%y(run%ny, 0), res%states(3, max(run%netot, 1), 0))
            call run_start(run, RUN_START_COLD, omega_start, omega_end, info, msg)
        end if
        cap = 0
        do while (info == 0 .and. run%status == RUN_GOING)
            call run_advance(run, int(s%batch, ip), pts, info, msg)
            do k = 1, pts%npts
                call keep(k)
            end do
        end do
        res%info = info
        res%message = msg
        if (info == 0) then
            res%complete = run%status == RUN_DONE
            res%message = run%message
            if (run%status == RUN_FAILED) res%info = run%fail_info
        end if
        call run_close(run)
        res%omega = res%omega(1:res%npts)
        res%xo = res%xo(:, :, 1:res%npts)
        res%amp = res%amp(:, 1:res%npts)
        res%y = res%y(:, 1:res%npts)
        res%states = res%states(:, :, 1:res%npts)
        res%iters = res%iters(1:res%npts)

    contains

        !> Keep point kk of the last advance (info = FRIROM_ERR_ALLOC if there is no room).
        subroutine keep(kk)
            integer(ip), intent(in) :: kk
            integer(ip) :: o, j
            if (res%npts == cap) then
                if (.not. grown(min(max(2*cap, 16_ip), int(s%max_points, ip)))) return
            end if
            res%npts = res%npts + 1
            j = res%npts
            res%omega(j) = pts%lam(kk)
            res%xo(:, :, j) = pts%xo(:, :, kk)
            do o = 1, nout
                res%amp(o, j) = peak_amplitude(pts%xo(o, :, kk))
            end do
            res%y(:, j) = pts%y(:, kk)
            res%states(:, :, j) = pts%states(:, :, kk)
            res%iters(j) = pts%iters(kk)
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
