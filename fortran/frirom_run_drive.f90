!> The continuation driver of frirom_run: starting a run (its first point and the
!> homotopy start), segments of points (frirom_hbm hbm_run), fold flags, stop reasons and
!> the stall test, and single corrector solves on the run's system.
submodule (frirom_run) frirom_run_drive
    use frirom_status, only: itoa
    use frirom_newton, only: cont_options, YSCALE_RELATIVE
    use frirom_hbm, only: hbm_lu_forget, hbm_lu_rebuild, hbm_run, hbm_sel_expand, hbm_sel_reduce, &
                          HBM_START_CONTINUE, HBM_START_RESUME, HBM_START_SOLVE_ONLY
    use frirom_epmc, only: hbm_epmc_guess
    implicit none

    !> Where a segment (one hbm_run call) starts and how far it may go.
    type :: seg_start
        integer(ip) :: mode = HBM_START_CONTINUE    !! HBM_START_*
        integer(ip) :: maxpts = 1
        real(wp), allocatable :: y(:), t(:)         !! full layout: (ny), (ny+1)
        real(wp) :: lam = 0.0_wp, ds = 0.0_wp, yscale = 1.0_wp
        real(wp) :: lam_end = 1.0_wp, lam_lo = 0.0_wp, lscale = 1.0_wp
        real(wp) :: ds_min = 0.0_wp, ds_max = 0.0_wp
        logical :: stability = .false.
    end type seg_start

contains

    module procedure run_start
        real(wp) :: nt
        info = FRIROM_OK
        if (.not. open_run(run, 'run_start', info, errmsg)) return
        run%timers = 0.0_wp
        if (.not. (abs(lam_start) <= huge(1.0_wp) .and. abs(lam_end) <= huge(1.0_wp)) &
            .or. lam_start == lam_end) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'lam_start, lam_end: finite '// &
                            'and different values expected')
            return
        end if
        if (run%m%mode == RUN_FREQUENCY .and. .not. (lam_start > 0.0_wp .and. &
                                                     lam_end > 0.0_wp)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'lam_start, lam_end: positive '// &
                            'frequencies (rad/s) expected')
            return
        end if
        if (present(y0)) then
            if (size(y0) /= run%ny .or. .not. all(abs(y0) <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'y0: the run''s unknowns '// &
                                '(finite) expected')
                return
            end if
        end if
        if (present(sliders)) then
            call run_set_sliders(run, sliders, info, errmsg)
            if (info /= 0) return
        end if
        run%lam_start = lam_start
        run%lam_end = lam_end
        run%lscale = abs(lam_end - lam_start)
        run%lam_lo = lam_start - 0.02_wp*(lam_end - lam_start)
        run%status = RUN_GOING
        run%fail_info = FRIROM_OK
        run%message = ''
        run%pending = .false.
        run%have_prev = .false.
        run%prev_t = 0.0_wp
        run%n_ring = 0
        run%n_before = 0
        run%n_made = 0
        run%ds = run%s%ds
        run%yscale = 1.0_wp
        if (allocated(run%y)) deallocate (run%y, run%t)
        allocate (run%y(run%ny), run%t(run%ny + 1))
        run%y = 0.0_wp
        run%t = 0.0_wp
        run%lam = lam_start
        if (present(lam0)) run%lam = lam0
        if (present(y0)) run%y = y0
        if (run%m%mode == RUN_MODE) then
            ! a nonlinear mode starts from its linear mode (run_set_nonlinear_mode)
            if (.not. allocated(run%m%mode_phi) .or. run%s%stability /= 0) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_start: a mode run '// &
                                'needs run_set_nonlinear_mode first, and stability off')
                return
            end if
            if (kind == RUN_START_COLD .or. .not. present(y0)) &
                call hbm_epmc_guess(run%sys, run%y)
        end if
        ! a run starts as one on a system just built: nothing of an earlier use is held
        call hbm_lu_forget(run%sys)
        run%lu_dirty = .false.
        select case (kind)
        case (RUN_START_COLD, RUN_START_POINT)
            call first_point(run, kind == RUN_START_COLD .or. .not. present(y0), info, errmsg)
        case (RUN_START_RESUME)
            if (.not. (present(y0) .and. present(tan0) .and. present(yscale) .and. &
                       present(lam0))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_start: a resume needs '// &
                                'the point (y0, lam0), its tangent and its yscale')
                return
            end if
            if (size(tan0) /= run%ny + 1 .or. .not. all(abs(tan0) <= huge(1.0_wp)) .or. &
                .not. (yscale > 0.0_wp .and. yscale <= huge(1.0_wp))) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'tan0, yscale: a finite '// &
                                'tangent of ny + 1 entries and a positive scale expected')
                return
            end if
            run%t = tan0
            run%prev_t = tan0(run%ny + 1)
            run%have_prev = .true.
            run%yscale = yscale
            if (present(n_before)) run%n_before = max(n_before, 0_ip)
            if (present(ds)) then
                if (ds > 0.0_wp) then
                    ! a checkpoint; the range changed since: the same direction
                    if (present(lscale_old)) then
                        if (lscale_old > 0.0_wp .and. lscale_old /= run%lscale) then
                            run%t(run%ny + 1) = run%t(run%ny + 1)*(lscale_old/run%lscale)
                            nt = norm2(run%t)
                            run%t = run%t/nt
                        end if
                    end if
                    run%ds = ds
                end if
            end if
            if (present(lu)) then
                ! the LU the checkpointed run held there: its path goes on unchanged
                call hbm_lu_rebuild(run%sys, lu, info, errmsg)
                if (info /= 0) then
                    errmsg = 'lu: '//trim(errmsg)
                    return
                end if
            end if
            run%start_mode = HBM_START_RESUME
        case default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_start: kind expected 0 '// &
                            '(cold), 1 (point) or 2 (resume)')
        end select
    end procedure run_start

    !> The first point: solved at the run's lam from run%y with a purely relative update
    !> test (no scale known yet); from the linear solution (cold) a failed Newton is
    !> retried from the homotopy start. The point is pending: the next segment continues
    !> from it and gives its tangent in the scale |y|.
    subroutine first_point(run, cold, info, errmsg)
        type(run_t), intent(inout) :: run
        logical, intent(in) :: cold
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(seg_start) :: st
        type(run_points) :: p1
        real(wp), allocatable :: yh(:)
        real(wp) :: dsout
        logical :: fin, ok
        call run_seg(run, st, HBM_START_SOLVE_ONLY, 1_ip, YSCALE_RELATIVE)
        call segment(run, st, p1, fin, dsout, info, errmsg)
        if (info /= 0 .and. run%m%mode == RUN_FREQUENCY .and. cold) then
            call homotopy(run, run%lam, yh, ok)
            if (ok) then
                st%y = yh
                call segment(run, st, p1, fin, dsout, info, errmsg)
            end if
        end if
        run%first = p1
        if (info /= 0) then
            run%status = RUN_FAILED
            run%fail_info = info
            run%message = errmsg
            return
        end if
        run%pending = .true.
        run%n_made = 1
        run%y = run%first%y(:, 1)
        run%t = 0.0_wp
        run%yscale = norm2(run%y)
        if (run%yscale == 0.0_wp) run%yscale = 1.0_wp
        run%start_mode = HBM_START_CONTINUE
    end subroutine first_point

    !> The unknowns at omega reached by load continuation of the dynamic excitation from 0
    !> to 1 from the static state (a second run on the same model, from the run's history);
    !> ok false if that fails too. The run's history becomes the one that path leaves.
    subroutine homotopy(run, omega, yh, ok)
        type(run_t), intent(inout) :: run
        real(wp), intent(in) :: omega
        real(wp), allocatable, intent(out) :: yh(:)
        logical, intent(out) :: ok
        type(run_t), allocatable :: child
        type(run_points) :: pts
        real(wp), allocatable :: wlast(:)
        integer(ip) :: info
        character(len=512) :: msg
        ok = .false.
        allocate (child)
        child%m = run%m
        child%s = run%s
        child%s%stability = 0
        child%m%mode = RUN_LOAD
        child%m%omega_fix = omega
        child%m%fe0(:, 2:) = 0.0_wp
        child%m%fe1 = run%m%fe0
        child%m%fe1(:, 1) = 0.0_wp
        if (run%nw > 0) then
            allocate (wlast(run%nw))
            call run_get_sliders(run, wlast)
            child%m%w0(1:run%nw) = wlast
        end if
        msg = ''
        call run_build(child, info, msg)
        if (info == 0) child%magic = RUN_MAGIC
        if (info == 0) call run_start(child, RUN_START_COLD, 0.0_wp, 1.0_wp, info, msg)
        allocate (yh(run%ny))
        do while (info == 0 .and. child%status == RUN_GOING)
            call run_advance(child, int(max(child%s%batch, 1), ip), pts, info, msg)
            if (pts%npts > 0) then
                yh = pts%y(:, pts%npts)
                if (run%nw > 0) wlast = pts%sliders(1:run%nw, pts%npts)
                ok = pts%lam(pts%npts) == 1.0_wp
            end if
        end do
        ok = ok .and. info == 0 .and. child%status == RUN_DONE
        call run_close(child)
        if (ok .and. run%nw > 0) call run_set_sliders(run, wlast, info, msg)
    end subroutine homotopy

    module procedure run_advance
        type(seg_start) :: st
        type(run_points) :: seg
        integer(ip) :: room, mx, np, j0, i, j, ne
        real(wp) :: dsout, tl
        logical :: fin
        character(len=64) :: buf
        character(len=8) :: unit
        info = FRIROM_OK
        call alloc_points(run, pts, 0_ip)
        if (.not. open_run(run, 'run_advance', info, errmsg)) return
        if (.not. allocated(run%y)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_advance: call run_start first')
            return
        end if
        if (k < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_advance: k, the points to '// &
                            'make, expected >= 1')
            return
        end if
        run%timers = 0.0_wp
        if (run%status /= RUN_GOING) return
        room = run%s%max_points - run%n_before - run%n_made
        if (room <= 0) then
            if (run%pending) then
                call alloc_points(run, pts, 1_ip)
                call copy_point(run%first, 1_ip, pts, 1_ip)
                run%pending = .false.
            end if
            call stop_max(run)
            return
        end if
        mx = min(k, room) + merge(1_ip, 0_ip, run%pending)
        if (run%lu_dirty) then
            ! a run_solve since the last segment: the LU the continuation held, again
            call hbm_lu_rebuild(run%sys, run%lu_saved, info, errmsg)
            run%lu_dirty = .false.
            if (info /= 0) return
        end if
        call run_seg(run, st, run%start_mode, mx, run%yscale)
        call segment(run, st, seg, fin, dsout, info, errmsg)
        np = seg%npts
        ! the pending first point takes its tangent from the segment's first point
        ne = np
        j0 = 1
        if (run%pending .and. np > 0) then
            j0 = 2
        else if (run%pending) then
            ne = 1
        end if
        call alloc_points(run, pts, ne)
        j = 0
        if (run%pending) then
            j = 1
            call copy_point(run%first, 1_ip, pts, 1_ip)
            if (np > 0) then
                pts%tan(:, 1) = seg%tan(:, 1)
                pts%yscale(1) = seg%yscale(1)
            end if
        end if
        do i = j0, np
            j = j + 1
            call copy_point(seg, i, pts, j)
            tl = seg%tan(run%ny + 1, i)
            if (run%have_prev .and. run%prev_t /= 0.0_wp) then
                if (sgn(tl) /= sgn(run%prev_t)) pts%fold(j) = 1
            end if
            run%prev_t = tl
            run%have_prev = .true.
        end do
        run%n_made = run%n_made + (np - j0 + 1)
        if (np > 0 .and. info == 0) pts%ds_next(ne) = dsout
        do i = 1, merge(ne, 0_ip, info == 0)
            if (stalled(run, pts, i)) then
                ! the points after the stall's are dropped: the run ends there
                pts%npts = i
                pts%ds_next(i) = 0.0_wp
                run%n_made = run%n_made - (ne - i)
                run%pending = .false.
                return
            end if
        end do
        run%pending = .false.
        if (info /= 0) then
            run%status = RUN_FAILED
            run%fail_info = info
            run%message = errmsg
            ! a run that made no point at all is an error of the call
            if (run%n_made > 0 .or. run%n_before > 0) then
                info = FRIROM_OK
            end if
            return
        end if
        if (run%n_made == 0) then
            run%status = RUN_DONE
            return
        end if
        ! the next segment starts from the last point, in the scale of its tangent
        run%y = pts%y(:, ne)
        run%lam = pts%lam(ne)
        run%t = pts%tan(:, ne)
        run%yscale = pts%yscale(ne)
        run%ds = dsout
        run%start_mode = HBM_START_RESUME
        unit = merge(' rad/s', '      ', run%m%mode == RUN_FREQUENCY)
        if (fin) then
            run%status = RUN_DONE
            if (run%lam /= run%lam_end) then
                run%status = RUN_LEFT_RANGE
                write (buf, '(g0.7)') run%lam
                run%message = 'the solution curve turned back and left the range through '// &
                              trim(adjustl(buf))//trim(unit)
                write (buf, '(g0.7)') run%lam_start
                run%message = trim(run%message)//' (start '//trim(adjustl(buf))//trim(unit)//')'
            end if
        else if (run%n_before + run%n_made >= run%s%max_points) then
            call stop_max(run)
        end if
    end procedure run_advance

    module procedure run_solve
        type(seg_start) :: st
        real(wp), allocatable :: wsave(:), yh(:)
        real(wp) :: dsout
        integer(ip) :: linfo
        logical :: fin, ok
        character(len=512) :: msg
        info = FRIROM_OK
        call alloc_points(run, pts, 0_ip)
        if (.not. open_run(run, 'run_solve', info, errmsg)) return
        run%timers = 0.0_wp
        if (size(y0) /= run%ny .or. .not. all(abs(y0) <= huge(1.0_wp)) .or. &
            .not. abs(lam0) <= huge(1.0_wp)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'run_solve: y0 (the run''s '// &
                            'unknowns) and lam0 finite expected')
            return
        end if
        allocate (wsave(max(run%nw, 1)))
        call run_get_sliders(run, wsave)
        if (run%status == RUN_GOING .and. allocated(run%y) .and. .not. run%lu_dirty) then
            ! the continuation's LU is made again before its next segment (run_advance)
            if (allocated(run%lu_saved)) deallocate (run%lu_saved)
            allocate (run%lu_saved(run_lu_size(run)))
            call run_lu_state(run, run%lu_saved)
            run%lu_dirty = .true.
        end if
        if (present(sliders)) then
            call run_set_sliders(run, sliders, info, errmsg)
            if (info /= 0) return
        end if
        st%y = y0
        st%lam = lam0
        st%maxpts = 1
        st%ds_min = run%s%ds_min
        st%ds_max = run%s%ds_max
        st%ds = run%s%ds
        st%stability = .false.
        if (present(stability)) st%stability = stability
        allocate (st%t(run%ny + 1))
        st%t = 0.0_wp
        select case (kind)
        case (RUN_SOLVE_FIXED)
            st%mode = HBM_START_SOLVE_ONLY
            st%yscale = YSCALE_RELATIVE
            st%lscale = abs(lam0)
            if (st%lscale == 0.0_wp) st%lscale = 1.0_wp
            st%lam_end = lam0 + 0.1_wp*st%lscale
            st%lam_lo = -huge(1.0_wp)
        case (RUN_SOLVE_STEP)
            if (.not. (present(tan0) .and. present(yscale) .and. present(ds))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_solve: a step needs '// &
                                'tan0, yscale and ds')
                return
            end if
            if (size(tan0) /= run%ny + 1 .or. .not. (ds > 0.0_wp .and. yscale > 0.0_wp)) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'run_solve: tan0 (ny + 1), '// &
                                'ds > 0 and yscale > 0 expected')
                return
            end if
            st%mode = HBM_START_RESUME
            st%t = tan0
            st%yscale = yscale
            st%ds = ds
            st%ds_min = 1.0e-12_wp
            st%ds_max = 1.0e3_wp
            st%lam_end = run%lam_end
            st%lam_lo = run%lam_lo
            st%lscale = run%lscale
        case default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_solve: kind expected 1 '// &
                            '(fixed parameter) or 2 (step)')
            return
        end select
        call segment(run, st, pts, fin, dsout, info, errmsg)
        if (info /= 0 .and. kind == RUN_SOLVE_FIXED .and. run%m%mode == RUN_FREQUENCY .and. &
            present(cold)) then
            if (cold) then
                call homotopy(run, lam0, yh, ok)
                if (ok) then
                    st%y = yh
                    call segment(run, st, pts, fin, dsout, info, errmsg)
                end if
            end if
        end if
        msg = ''
        call run_set_sliders(run, wsave(1:run%nw), linfo, msg)
    end procedure run_solve

    !> A segment from the run's continuation state, within its range and settings.
    subroutine run_seg(run, st, mode, maxpts, yscale)
        type(run_t), intent(in) :: run
        type(seg_start), intent(out) :: st
        integer(ip), intent(in) :: mode, maxpts
        real(wp), intent(in) :: yscale
        st%mode = mode
        st%maxpts = maxpts
        st%y = run%y
        st%t = run%t
        st%lam = run%lam
        st%ds = run%ds
        st%yscale = yscale
        st%lam_end = run%lam_end
        st%lam_lo = run%lam_lo
        st%lscale = run%lscale
        st%ds_min = run%s%ds_min
        st%ds_max = run%s%ds_max
        st%stability = run%s%stability /= 0
    end subroutine run_seg

    !> One hbm_run call from st: its points into pts (full layout), whether it reached
    !> lam_end, the step it ends with; the run's timers add its time.
    subroutine segment(run, st, pts, fin, dsout, info, errmsg)
        type(run_t), intent(inout) :: run
        type(seg_start), intent(in) :: st
        type(run_points), intent(inout) :: pts
        logical, intent(out) :: fin
        real(wp), intent(out) :: dsout
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        type(cont_options) :: o
        real(wp), allocatable :: y(:), t(:), ys(:, :), tans(:, :), hill(:), lk(:)
        real(wp) :: lam
        integer(ip) :: n, ny, mx, np, k
        integer(8) :: c0, c1, rate
        call system_clock(c0, rate)
        n = run%sys%n
        ny = run%ny
        mx = st%maxpts
        o%tol_r = run%s%tol_residual
        o%tol_x = run%s%tol_update
        o%tol_stall = run%s%tol_stall
        o%max_iter = run%s%max_iter
        o%reuse_jac = run%s%reuse_jacobian /= 0
        o%yscale = st%yscale
        o%lscale = st%lscale
        o%ds = st%ds
        o%ds_min = st%ds_min
        o%ds_max = st%ds_max
        o%lam_end = st%lam_end
        o%max_points = mx
        call alloc_points(run, pts, mx)
        allocate (y(n), t(n + 1), ys(n, mx), tans(n + 1, mx))
        call hbm_sel_reduce(run%sys, st%y, y)
        call hbm_sel_reduce(run%sys, st%t(1:ny), t(1:n))
        t(n + 1) = st%t(ny + 1)
        lam = st%lam
        dsout = st%ds
        run%sys%carry = run%s%history /= 0
        run%sys%orient = run%m%mode /= RUN_MODE
        run%sys%timers = 0.0_wp
        if (st%stability) allocate (hill(mx))
        if (allocated(run%m%keep)) allocate (lk(mx))
        call hbm_run(run%sys, st%mode, y, lam, t, dsout, st%lam_lo, o, ys, pts%lam, &
                     tans, pts%iters, pts%xo, pts%states, np, fin, info, errmsg, hill, &
                     sliders=pts%sliders, yscales=pts%yscale, leak=lk)
        pts%npts = np
        do k = 1, np
            call hbm_sel_expand(run%sys, ys(:, k), pts%y(:, k))
            call hbm_sel_expand(run%sys, tans(1:n, k), pts%tan(1:ny, k))
            pts%tan(ny + 1, k) = tans(n + 1, k)
        end do
        if (allocated(hill)) pts%hill = hill
        if (allocated(lk)) pts%leak = lk
        run%timers(1:N_TIMERS - 1) = run%timers(1:N_TIMERS - 1) + run%sys%timers(1:N_TIMERS - 1)
        call system_clock(c1)
        run%timers(N_TIMERS) = run%timers(N_TIMERS) + real(c1 - c0, wp)/real(rate, wp)
    end subroutine segment

    !> pts with room for n points of this run, zeroed.
    subroutine alloc_points(run, pts, n)
        type(run_t), intent(in) :: run
        type(run_points), intent(inout) :: pts
        integer(ip), intent(in) :: n
        integer(ip) :: nc
        nc = 2*run%m%nh + 1
        pts = run_points()
        pts%npts = n
        allocate (pts%y(run%ny, n), pts%lam(n), pts%tan(run%ny + 1, n), &
                  pts%xo(run%nout, nc, n), pts%states(3, max(run%netot, 1), n), pts%hill(n), &
                  pts%sliders(max(run%nw, 1), n), pts%yscale(n), pts%leak(n), &
                  pts%ds_next(n), source=0.0_wp)
        allocate (pts%iters(n), pts%fold(n), source=0_ip)
    end subroutine alloc_points

    !> Point i of a into point j of b.
    subroutine copy_point(a, i, b, j)
        type(run_points), intent(in) :: a
        integer(ip), intent(in) :: i, j
        type(run_points), intent(inout) :: b
        b%y(:, j) = a%y(:, i)
        b%lam(j) = a%lam(i)
        b%tan(:, j) = a%tan(:, i)
        b%iters(j) = a%iters(i)
        b%xo(:, :, j) = a%xo(:, :, i)
        b%states(:, :, j) = a%states(:, :, i)
        b%hill(j) = a%hill(i)
        b%sliders(:, j) = a%sliders(:, i)
        b%yscale(j) = a%yscale(i)
        b%leak(j) = a%leak(i)
        b%ds_next(j) = a%ds_next(i)
        b%fold(j) = a%fold(i)
    end subroutine copy_point

    !> Note point i of pts in the run's ring; true (status RUN_STALLED, the diagnosis in
    !> run%message) when the last STALL_POINTS points moved the parameter by less than
    !> STALL_PROGRESS of the range. The diagnosis: the unknowns drift while the parameter
    !> and the outputs stay fixed, a family of solutions at one parameter (a direction the
    !> equations leave free, such as the mean position of a body held only by friction
    !> contacts in gross slip); the outputs change too, the curve turns in place (a
    !> singular direction); neither, steps at the tolerance floor.
    logical function stalled(run, pts, i)
        type(run_t), intent(inout) :: run
        type(run_points), intent(in) :: pts
        integer(ip), intent(in) :: i
        integer(ip) :: at, n
        real(wp) :: dl, dy, dx, ymax, xmax
        character(len=16) :: b1, b2, b3
        stalled = .false.
        at = modulo(run%n_ring, STALL_POINTS) + 1
        run%ring(:, at) = [pts%lam(i), norm2(pts%y(:, i)), norm2(pts%xo(:, :, i))]
        run%n_ring = run%n_ring + 1
        if (run%n_ring < STALL_POINTS) return
        dl = maxval(run%ring(1, :)) - minval(run%ring(1, :))
        if (dl >= STALL_PROGRESS*run%lscale) return
        stalled = .true.
        n = STALL_POINTS
        ymax = max(maxval(run%ring(2, :)), tiny(1.0_wp))
        xmax = max(maxval(run%ring(3, :)), tiny(1.0_wp))
        dy = (maxval(run%ring(2, :)) - minval(run%ring(2, :)))/ymax
        dx = (maxval(run%ring(3, :)) - minval(run%ring(3, :)))/xmax
        write (b1, '(es9.2)') dl/run%lscale
        write (b2, '(es9.2)') dy
        write (b3, '(es9.2)') dx
        run%status = RUN_STALLED
        run%message = 'no progress in the parameter: its last '//trim(itoa(n))// &
                      ' points moved it by '//trim(adjustl(b1))//' of the range'
        if (dy > 1.0e3_wp*dx .and. dy > 1.0e-6_wp) then
            run%message = trim(run%message)//'; the unknowns drift ('//trim(adjustl(b2))// &
                ') while the outputs stay fixed ('//trim(adjustl(b3))//'): a family of '// &
                'solutions at one parameter, a direction the equations leave free (e.g. '// &
                'the mean position of a body held only by friction contacts in gross '// &
                'slip). More points or a resume repeat it: hold that direction (a '// &
                'grounded stiffness, or contacts that stick)'
        else if (dx > 1.0e-6_wp) then
            run%message = trim(run%message)//'; the unknowns ('//trim(adjustl(b2))// &
                ') and the outputs ('//trim(adjustl(b3))//') change at a fixed parameter: '// &
                'the curve turns in place (a singular direction). A smaller ds_max, or '// &
                'more harmonics or samples where contact states switch, may pass it'
        else
            run%message = trim(run%message)//'; neither the unknowns nor the outputs '// &
                'change: steps at the tolerance floor. A larger tol_stall or more samples '// &
                'may pass it'
        end if
    end function stalled


    subroutine stop_max(run)
        type(run_t), intent(inout) :: run
        character(len=16) :: buf
        write (buf, '(i0)') run%s%max_points
        run%status = RUN_MAX_POINTS
        run%message = 'stopped after max_points = '//trim(buf)//' points'
    end subroutine stop_max


    !> -1, 0 or 1 (numpy's sign).
    pure real(wp) function sgn(x)
        real(wp), intent(in) :: x
        sgn = merge(1.0_wp, merge(-1.0_wp, 0.0_wp, x < 0.0_wp), x > 0.0_wp)
    end function sgn

end submodule frirom_run_drive
