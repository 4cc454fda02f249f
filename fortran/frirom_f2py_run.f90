! The run object's calls for f2py (frirom_run): open, set modes / free bodies / selection,
! start, advance, solve, LU state and close on an opaque handle. f2py reads this file and
! frirom_f2py.f90 into one extension module (frirom._kernels), under the same rules: plain
! subroutines with explicit-shape arrays and real(8) / integer(4) dummies, `info` plus the
! library's message, no derived type crossing.

!> Open a run on a model (frirom_run run_open; Python's frirom.solver drives it): the
!> model as plain arrays. formulation: 1 condensed (Eq. 5-9), 2 banded; mode: 1 frequency
!> (lam = omega, excitation fe0), 2 load (fe0 + lam fe1 at omega_fix). K, M, C: CSR,
!> 1-based, ndof x ndof, symmetric; perm: RCM order of the DoFs; nl: nonlinear DoFs
!> (condensed); tcontact: condensed unknowns in contact coordinates G x; krylov: GMRES
!> solves preconditioned by an older LU; sparse: receptances by MUMPS. ginfo(3, ngroup):
!> law, n_elem, n_dir; G rows group by group, element, direction; params and w0 per group,
!> concatenated. iset, rset: the settings (settings_defaults' layout). Out: the handle
!> (0 when info /= 0), unknowns per point ny, sliders nw, contact elements netot.
subroutine frun_open(formulation, mode, nh, nsamp, ndof, nnzk, kp, ki, kx, nnzm, mp, mi, mx, &
                    nnzc, cp, ci, cx, perm, nnl, nl, fe0, fe1, omega_fix, ngroup, ginfo, &
                    nrows, nnzg, gp, gi, gx, npart, params, nw0, w0, nout, outdofs, &
                    tcontact, krylov, sparse, niset, iset, nrset, rset, handle, ny, nw, &
                    netot, info, msg)
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_ERR_SIZE, set_status
    use frirom_run, only: run_t, fr_open => run_open, run_handle, settings_unpack, N_ISET, &
                          N_RSET
    implicit none
    integer(4), intent(in) :: formulation, mode, nh, nsamp, ndof, nnzk, nnzm, nnzc
    integer(4), intent(in) :: kp(ndof + 1), ki(nnzk), mp(ndof + 1), mi(nnzm), cp(ndof + 1), &
                              ci(nnzc)
    real(8), intent(in) :: kx(nnzk), mx(nnzm), cx(nnzc)
    integer(4), intent(in) :: perm(ndof), nnl, nl(nnl)
    real(8), intent(in) :: fe0(ndof, 2*nh + 1), fe1(ndof, 2*nh + 1), omega_fix
    integer(4), intent(in) :: ngroup, ginfo(3, ngroup), nrows, nnzg, gp(nrows + 1), gi(nnzg)
    real(8), intent(in) :: gx(nnzg)
    integer(4), intent(in) :: npart, nw0, nout, outdofs(nout)
    real(8), intent(in) :: params(npart), w0(nw0)
    integer(4), intent(in) :: tcontact, krylov, sparse
    integer(4), intent(in) :: niset, iset(niset), nrset
    real(8), intent(in) :: rset(nrset)
    integer(8), intent(out) :: handle
    integer(4), intent(out) :: ny, nw, netot, info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    msg = ''
    handle = 0
    ny = 0
    nw = 0
    netot = 0
    if (niset /= N_ISET .or. nrset /= N_RSET .or. iset(1) /= nh) then
        call set_status(linfo, FRIROM_ERR_SIZE, msg, 'run_open: iset, rset need the '// &
                        'settings_defaults layout, iset(1) = nh')
        info = linfo
        return
    end if
    allocate (r)
    call fr_open(r, settings_unpack(int(iset, ip), rset), int(formulation, ip), int(mode, ip), &
                 int(nsamp, ip), int(ndof, ip), int(kp, ip), int(ki, ip), kx, int(mp, ip), &
                 int(mi, ip), mx, int(cp, ip), int(ci, ip), cx, int(perm, ip), int(nl, ip), &
                 fe0, fe1, omega_fix, int(ginfo, ip), int(gp, ip), int(gi, ip), gx, params, &
                 w0, int(outdofs, ip), tcontact == 1, int(krylov, ip), sparse == 1, linfo, msg)
    info = linfo
    if (linfo /= 0) then
        deallocate (r)
        return
    end if
    ny = r%ny
    nw = r%nw
    netot = r%netot
    handle = run_handle(r)
end subroutine frun_open

!> Receptances of an open run by modal superposition: harmonic = 0, nmodes real
!> mass-normalised modes phi with wmodes (rad/s) and zmodes (ratios); harmonic = 1,
!> modes of their own per harmonic (a cyclic sector): psi(:, :, h + 1) complex shapes of
!> harmonic h's nodal diameter, wmodes and zmodes (nmodes, nh1) (the unused kind's arrays
!> may be 1 x 1 dummies).
subroutine frun_set_modes(handle, harmonic, ndof, nmodes, nh1, phi, psi, npsi, wmodes, &
                          zmodes, info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_modes => run_set_modes, &
                          fr_hmodes => run_set_modes_harmonic
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: harmonic, ndof, nmodes, nh1, npsi
    real(8), intent(in) :: phi(ndof, nmodes), wmodes(nmodes, nh1), zmodes(nmodes, nh1)
    complex(8), intent(in) :: psi(npsi, nmodes, nh1)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    call run_from_handle(handle, r, 'run_set_modes', linfo, msg)
    if (linfo == 0 .and. harmonic == 1) then
        call fr_hmodes(r, psi, wmodes, zmodes, linfo, msg)
    else if (linfo == 0) then
        call fr_modes(r, phi, wmodes(:, 1), zmodes(:, 1), linfo, msg)
    end if
    info = linfo
end subroutine frun_set_modes

!> Bodies held only by their contacts (on = 1): frirom_run run_set_free_bodies.
subroutine frun_set_free_bodies(handle, on, info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_free => run_set_free_bodies
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: on
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    call run_from_handle(handle, r, 'run_set_free_bodies', linfo, msg)
    if (linfo == 0) call fr_free(r, on == 1, linfo, msg)
    info = linfo
end subroutine frun_set_free_bodies

!> A travelling-wave selection keep(j, h + 1) = 1 of the nonlinear DoFs' harmonics; with
!> haspair = 1 its direction pair (0: none); with orbits = 1 Newton's evaluations on one
!> element per orbit (matched to orbtol). orbinfo: elements the AFT runs on, misfit.
subroutine frun_set_selection(handle, nnl, nh1, keep, pair, haspair, orbits, orbtol, orbinfo, &
                             info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_select => run_set_selection
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: nnl, nh1, keep(nnl, nh1), pair(nnl, nh1), haspair, orbits
    real(8), intent(in) :: orbtol
    real(8), intent(out) :: orbinfo(2)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    integer(ip), allocatable :: pr(:, :)     ! unallocated: no pair (absent)
    msg = ''
    orbinfo = 0.0d0
    if (haspair == 1) pr = int(pair, ip)
    call run_from_handle(handle, r, 'run_set_selection', linfo, msg)
    if (linfo == 0) call fr_select(r, int(keep, ip), linfo, msg, pair=pr, &
                                   orbits=orbits == 1, orbtol=orbtol)
    if (linfo == 0) orbinfo = [real(r%orb_nrep, 8), r%orb_mis]
    info = linfo
end subroutine frun_set_selection

!> Start a continuation of an open run from lam_start to lam_end (frirom_run run_start):
!> kind 0 cold, 1 from the point y0 at lam0 (solved first), 2 resumed from y0 at lam0 with
!> tangent tan0 in scale yscale (a checkpoint: ds > 0 its step, lscale_old > 0 the range
!> of the run that wrote it, n_before its points). hassliders = 1: start from the history
!> sliders. timings (N_TIMERS) of the call.
subroutine frun_start(handle, kind, lam_start, lam_end, lam0, ny, y0, tan0, yscale, ds, &
                     lscale_old, n_before, nw, sliders, hassliders, nlu, lu, ntim, timings, &
                     info, msg)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_start => run_start
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: kind, ny, n_before, nw, hassliders, nlu, ntim
    real(8), intent(in) :: lam_start, lam_end, lam0, y0(ny), tan0(ny + 1), yscale, ds, &
                           lscale_old, sliders(nw), lu(nlu)
    real(8), intent(out) :: timings(ntim)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    real(8), allocatable :: sl(:)            ! unallocated: the run's own history (absent)
    msg = ''
    timings = 0.0d0
    if (hassliders == 1) sl = sliders
    call run_from_handle(handle, r, 'run_start', linfo, msg)
    if (linfo == 0 .and. nlu > 0) then
        ! a checkpoint's held LU (frun_lu_state)
        call fr_start(r, int(kind, ip), lam_start, lam_end, linfo, msg, &
                      lam0=lam0, y0=y0, tan0=tan0, yscale=yscale, ds=ds, &
                      lscale_old=lscale_old, n_before=int(n_before, ip), sliders=sl, lu=lu)
    else if (linfo == 0) then
        call fr_start(r, int(kind, ip), lam_start, lam_end, linfo, msg, &
                      lam0=lam0, y0=y0, tan0=tan0, yscale=yscale, ds=ds, &
                      lscale_old=lscale_old, n_before=int(n_before, ip), sliders=sl)
    end if
    if (associated(r)) timings(1:min(ntim, size(r%timers))) = r%timers(1:min(ntim, size(r%timers)))
    info = linfo
end subroutine frun_start

!> Length of a run's held-LU state (frirom_run run_lu_size); 0 for a bad handle.
subroutine frun_lu_size(handle, n)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, run_lu_size
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(out) :: n
    type(run_t), pointer :: r
    integer(ip) :: linfo
    character(len=512) :: msg
    n = 0
    msg = ''
    call run_from_handle(handle, r, 'run_lu_size', linfo, msg)
    if (linfo == 0) n = int(run_lu_size(r), 4)
end subroutine frun_lu_size

!> The state of the LU a run's continuation holds (frirom_run run_lu_state), for a
!> checkpoint: frun_start's lu makes it again, so a resumed run goes on bit for bit.
subroutine frun_lu_state(handle, n, v, info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_SIZE, set_status
    use frirom_run, only: run_t, run_from_handle, run_lu_size, run_lu_state
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: n
    real(8), intent(out) :: v(n)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    integer(ip) :: linfo
    v = 0.0d0
    call run_from_handle(handle, r, 'run_lu_state', linfo, msg)
    if (linfo == 0) then
        if (n /= run_lu_size(r)) then
            call set_status(linfo, FRIROM_ERR_SIZE, msg, 'run_lu_state: n, the state''s '// &
                            'length (frun_lu_size), expected')
        else
            call run_lu_state(r, v)
        end if
    end if
    info = linfo
end subroutine frun_lu_state

!> Up to k more points of a started run (frirom_run run_advance) into arrays of room
!> maxpts >= k + 1: npts points; status (RUN_*: 0 going, 1 done, 2 max_points, 3 left the
!> range, 4 failed, 5 stalled), fail_info the failure's code and message its text (or why it
!> stopped); advice (ADVISE_* bits) and stalled (|R|/rref, -1: none) of a failure at ds_min;
!> fold(k) = 1 where the tangent turned; ds_next(k) > 0 at a checkpoint.
subroutine frun_advance(handle, k, maxpts, ny, nout, nc, netot, nw, ys, lams, tans, iters, &
                       xo, states, hill_re, sliders, yscales, leak, ds_next, fold, npts, &
                       status, fail_info, message, advice, stalled, ntim, timings, info, msg)
    use frirom_kinds, only: ip, wp
    use frirom_status, only: FRIROM_ERR_SIZE, set_status
    use frirom_run, only: run_t, run_points, run_from_handle, fr_advance => run_advance, &
                          run_advice
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: k, maxpts, ny, nout, nc, netot, nw, ntim
    real(8), intent(out) :: ys(ny, maxpts), lams(maxpts), tans(ny + 1, maxpts)
    integer(4), intent(out) :: iters(maxpts), fold(maxpts)
    real(8), intent(out) :: xo(nout, nc, maxpts), states(3, netot, maxpts), hill_re(maxpts)
    real(8), intent(out) :: sliders(nw, maxpts), yscales(maxpts), leak(maxpts), &
                           ds_next(maxpts)
    integer(4), intent(out) :: npts, status, fail_info, advice
    character(len=512), intent(out) :: message
    real(8), intent(out) :: stalled, timings(ntim)
    integer(4), intent(out) :: info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    type(run_points) :: p
    integer(ip) :: linfo, bits
    real(wp) :: st
    msg = ''
    message = ''
    npts = 0
    status = 0
    fail_info = 0
    advice = 0
    stalled = -1.0d0
    timings = 0.0d0
    call run_from_handle(handle, r, 'run_advance', linfo, msg)
    if (linfo == 0) then
        if (maxpts < k + 1 .or. ny /= r%ny .or. nout /= r%nout .or. &
            nc /= 2*r%m%nh + 1 .or. netot /= max(r%netot, 1) .or. nw /= max(r%nw, 1)) &
            call set_status(linfo, FRIROM_ERR_SIZE, msg, 'run_advance: array sizes do '// &
                            'not match the run (maxpts >= k + 1)')
    end if
    if (linfo == 0) call fr_advance(r, int(k, ip), p, linfo, msg)
    if (associated(r)) then
        npts = int(p%npts, 4)
        if (npts > 0) then
            ys(:, 1:npts) = p%y
            lams(1:npts) = p%lam
            tans(:, 1:npts) = p%tan
            iters(1:npts) = int(p%iters, 4)
            xo(:, :, 1:npts) = p%xo
            states(:, :, 1:npts) = p%states
            hill_re(1:npts) = p%hill
            sliders(:, 1:npts) = p%sliders
            yscales(1:npts) = p%yscale
            leak(1:npts) = p%leak
            ds_next(1:npts) = p%ds_next
            fold(1:npts) = int(p%fold, 4)
        end if
        status = int(r%status, 4)
        fail_info = int(r%fail_info, 4)
        message = r%message
        call run_advice(r, bits, st)
        advice = int(bits, 4)
        stalled = st
        timings(1:min(ntim, size(r%timers))) = r%timers(1:min(ntim, size(r%timers)))
    end if
    info = linfo
end subroutine frun_advance

!> One corrector on an open run's system (frirom_run run_solve), its continuation state
!> untouched: kind 1 at lam0 from y0 (cold = 1: from the linear solution, with the
!> homotopy start when Newton fails); kind 2 a step ds along tan0 (scale yscale) from the
!> point (y0, lam0) of a started run. hassliders = 1: from the history sliders.
!> stability = 1: Hill's method at the point. Out: the point.
subroutine frun_solve(handle, kind, lam0, ny, y0, tan0, yscale, ds, nw, sliders, hassliders, &
                     stability, cold, nout, nc, netot, y, lam, tan, iters, xo, states, &
                     hill_re, slider_out, yscale_out, leak, ntim, timings, info, msg)
    use frirom_kinds, only: ip
    use frirom_status, only: FRIROM_ERR_SIZE, set_status
    use frirom_run, only: run_t, run_points, run_from_handle, fr_solve => run_solve
    implicit none
    integer(8), intent(in) :: handle
    integer(4), intent(in) :: kind, ny, nw, hassliders, stability, cold, nout, nc, netot, ntim
    real(8), intent(in) :: lam0, y0(ny), tan0(ny + 1), yscale, ds, sliders(nw)
    real(8), intent(out) :: y(ny), lam, tan(ny + 1), xo(nout, nc), states(3, netot), &
                            hill_re, slider_out(nw), yscale_out, leak, timings(ntim)
    integer(4), intent(out) :: iters, info
    character(len=512), intent(out) :: msg
    type(run_t), pointer :: r
    type(run_points) :: p
    integer(ip) :: linfo
    real(8), allocatable :: sl(:)            ! unallocated: the run's own history (absent)
    msg = ''
    y = 0.0d0
    lam = 0.0d0
    tan = 0.0d0
    xo = 0.0d0
    states = 0.0d0
    hill_re = 0.0d0
    slider_out = 0.0d0
    yscale_out = 0.0d0
    leak = 0.0d0
    iters = 0
    timings = 0.0d0
    call run_from_handle(handle, r, 'run_solve', linfo, msg)
    if (linfo == 0) then
        if (ny /= r%ny .or. nout /= r%nout .or. nc /= 2*r%m%nh + 1 .or. &
            netot /= max(r%netot, 1) .or. nw /= max(r%nw, 1)) &
            call set_status(linfo, FRIROM_ERR_SIZE, msg, 'run_solve: array sizes do not '// &
                            'match the run')
    end if
    if (hassliders == 1 .and. associated(r)) sl = sliders(1:r%nw)
    if (linfo == 0) call fr_solve(r, int(kind, ip), lam0, y0, p, linfo, msg, tan0=tan0, &
                                  yscale=yscale, ds=ds, sliders=sl, &
                                  stability=stability == 1, cold=cold == 1)
    if (linfo == 0 .and. p%npts /= 1) call set_status(linfo, FRIROM_ERR_SIZE, msg, &
                                                      'run_solve: no point')
    if (linfo == 0) then
        y = p%y(:, 1)
        lam = p%lam(1)
        tan = p%tan(:, 1)
        iters = int(p%iters(1), 4)
        xo = p%xo(:, :, 1)
        states = p%states(:, :, 1)
        hill_re = p%hill(1)
        slider_out = p%sliders(:, 1)
        yscale_out = p%yscale(1)
        leak = p%leak(1)
    end if
    if (associated(r)) timings(1:min(ntim, size(r%timers))) = r%timers(1:min(ntim, size(r%timers)))
    info = linfo
end subroutine frun_solve

!> Close a run (frirom_run run_close) and free it; a handle of no open run is ignored.
subroutine frun_close(handle)
    use frirom_kinds, only: ip
    use frirom_run, only: run_t, run_from_handle, fr_close => run_close
    implicit none
    integer(8), intent(in) :: handle
    type(run_t), pointer :: r
    integer(ip) :: linfo
    character(len=512) :: msg
    msg = ''
    call run_from_handle(handle, r, 'run_close', linfo, msg)
    if (linfo /= 0) return
    call fr_close(r)
    deallocate (r)
end subroutine frun_close
