!> Opening and building a run of frirom_run: the model's arrays checked and kept, the
!> system built from them (hbm_setup), its receptance modes and its travelling-wave
!> selection (with the orbits), and the settings' ranges.
submodule (frirom_run) frirom_run_setup
    use frirom_hbm, only: hbm_condensed, hbm_full, hbm_setup, hbm_set_modes, &
                          hbm_set_modes_harmonic, hbm_set_selection, hbm_set_orbits
    use frirom_epmc, only: hbm_epmc, hbm_epmc_set, hbm_epmc_modal, hbm_epmc_modal_set
    use frirom_aft, only: aft_plan_destroy, law_nslider
    implicit none

contains

    module procedure run_open
        info = FRIROM_OK
        call run_close(run)
        call check_settings(s, info, errmsg)
        if (info /= 0) return
        if (formulation /= RUN_CONDENSED .and. formulation /= RUN_BANDED) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'formulation: expected 1 '// &
                            '(condensed) or 2 (banded)')
        else if (mode /= RUN_FREQUENCY .and. mode /= RUN_LOAD .and. mode /= RUN_MODE) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'mode: expected 1 (frequency), '// &
                            '2 (load) or 3 (nonlinear mode)')
        else if (mode == RUN_MODE .and. (krylov == 1 .or. sparse)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'mode 3 (nonlinear mode): '// &
                            'dense solves only (krylov and sparse off)')
        else if (ndof < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'ndof: expected at least 1 DoF')
        else if (nsamp < 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nsamp: expected >= 0 (0: default)')
        else if (size(fe0, 1) /= ndof .or. size(fe0, 2) /= 2*s%harmonics + 1 .or. &
                 any(shape(fe1) /= shape(fe0))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'fe0, fe1: expected (ndof, '// &
                            '2 harmonics + 1) arrays')
        else if (.not. (all(abs(fe0) <= huge(1.0_wp)) .and. all(abs(fe1) <= huge(1.0_wp)) &
                        .and. abs(omega_fix) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'fe0, fe1, omega_fix: NaN or Inf')
        else if (.not. (all(abs(kx) <= huge(1.0_wp)) .and. all(abs(mx) <= huge(1.0_wp)) &
                        .and. all(abs(cx) <= huge(1.0_wp)))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'K, M, C: NaN or Inf entries')
        else if (.not. (all(abs(gx) <= huge(1.0_wp)) .and. all(abs(params) <= huge(1.0_wp)) &
                        .and. all(abs(w0) <= huge(1.0_wp)))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'G, params, w0: NaN or Inf '// &
                            'entries')
        end if
        if (info /= 0) return
        run%s = s
        associate (m => run%m)
            m%formulation = formulation
            m%mode = mode
            m%nh = s%harmonics
            m%nsamp = nsamp
            if (nsamp == 0) m%nsamp = run_default_samples(m%nh)
            m%ndof = ndof
            m%krylov = krylov
            m%omega_fix = omega_fix
            m%tcontact = tcontact
            m%sparse = sparse
            m%kp = kp
            m%ki = ki
            m%kx = kx
            m%mp = mp
            m%mi = mi
            m%mx = mx
            m%cp = cp
            m%ci = ci
            m%cx = cx
            m%perm = perm
            m%nl = nl
            m%fe0 = fe0
            m%fe1 = fe1
            m%ginfo = ginfo
            m%gp = gp
            m%gi = gi
            m%gx = gx
            m%params = params
            m%w0 = w0
            m%outdofs = outdofs
        end associate
        call run_build(run, info, errmsg)
        if (info == 0) run%magic = RUN_MAGIC
    end procedure run_open

    module procedure run_build
        integer(ip) :: g
        info = FRIROM_OK
        if (allocated(run%sys)) then
            call aft_plan_destroy(run%sys%plan)
            deallocate (run%sys)
        end if
        run%built = .false.
        associate (m => run%m)
            if (m%mode == RUN_MODE .and. m%formulation == RUN_CONDENSED) then
                allocate (hbm_epmc_modal :: run%sys)
            else if (m%mode == RUN_MODE) then
                allocate (hbm_epmc :: run%sys)
            else if (m%formulation == RUN_CONDENSED) then
                allocate (hbm_condensed :: run%sys)
            else
                allocate (hbm_full :: run%sys)
            end if
            call hbm_setup(run%sys, m%nh, m%nsamp, m%ndof, m%kp, m%ki, m%kx, m%mp, m%mi, &
                           m%mx, m%cp, m%ci, m%cx, m%perm, m%nl, m%fe0, m%fe1, &
                           merge(RUN_FREQUENCY, m%mode, m%mode == RUN_MODE), &
                           m%omega_fix, m%ginfo, m%gp, m%gi, m%gx, m%params, m%w0, &
                           m%outdofs, info, errmsg, contact_coords=m%tcontact, &
                           krylov=m%krylov, sparse_lu=m%sparse, free_bodies=m%free)
            if (info /= 0) return
            ! stability 2: Hill's whole strip on reduced models (else the exponents near 0)
            run%sys%hill_strip = run%s%stability == 2
            run%sys%cs%ulaw = m%ulaw
            if (allocated(m%phi)) call hbm_set_modes(run%sys, m%phi, m%wm, m%zm, info, errmsg)
            if (info /= 0) return
            if (allocated(m%psi)) call hbm_set_modes_harmonic(run%sys, m%psi, m%wh, m%zh, &
                                                              info, errmsg)
            if (info /= 0) return
            if (allocated(m%mode_modes)) then
                call hbm_epmc_modal_set(run%sys, m%mode_phi, m%mode_w0, m%mode_modes, &
                                        m%mode_wm, m%mode_zm, m%nl, info, errmsg)
            else if (allocated(m%mode_phi)) then
                call hbm_epmc_set(run%sys, m%mode_phi, m%mode_w0, info, errmsg)
            end if
            if (info /= 0) return
            run%netot = sum(m%ginfo(2, :))
            if (allocated(m%keep)) call apply_selection(run, info, errmsg)
            if (info /= 0) return
            run%nout = size(m%outdofs)
        end associate
        select type (sys => run%sys)
        type is (hbm_condensed)
            run%ny = sys%nnl*sys%nc
        class default
            run%ny = sys%n
        end select
        run%nw = 0
        do g = 1, size(run%sys%cs%grp)
            run%nw = run%nw + law_nslider(run%sys%cs%grp(g)%law)*run%sys%cs%grp(g)%ne
        end do
        run%built = .true.
    end procedure run_build

    module procedure run_set_modes
        if (.not. modes_ok(run, size(phi, 1) /= run%m%ndof .or. size(phi, 2) < 1 .or. &
                           any(shape(wm) /= [size(phi, 2)]) .or. &
                           any(shape(zm) /= [size(phi, 2)]), &
                           all(abs(phi) <= huge(1.0_wp)) .and. good_modes(wm, zm), &
                           'run_set_modes: phi (ndof, nm), omega and zeta (nm)', info, &
                           errmsg)) return
        run%m%phi = phi
        run%m%wm = wm
        run%m%zm = zm
        call apply_modes(run, .false., info, errmsg)
        if (info /= 0) deallocate (run%m%phi, run%m%wm, run%m%zm)
    end procedure run_set_modes

    module procedure run_set_modes_harmonic
        if (.not. modes_ok(run, size(psi, 1) /= run%m%ndof .or. size(psi, 3) /= &
                           run%m%nh + 1 .or. any(shape(wh) /= [size(psi, 2), size(psi, 3)]) &
                           .or. any(shape(zh) /= shape(wh)), all(abs(psi) <= huge(1.0_wp)) &
                           .and. good_modes(reshape(wh, [size(wh)]), reshape(zh, &
                           [size(zh)])), 'run_set_modes_harmonic: psi (ndof, nm, H+1), '// &
                           'omega and zeta (nm, H+1)', info, errmsg)) return
        run%m%psi = psi
        run%m%wh = wh
        run%m%zh = zh
        call apply_modes(run, .true., info, errmsg)
        if (info /= 0) deallocate (run%m%psi, run%m%wh, run%m%zh)
    end procedure run_set_modes_harmonic

    !> An open run and modes of the sizes (bad_size false) and values (good) expected;
    !> else info (FRIROM_ERR_SIZE or _PARAM) with `what` in the message.
    logical function modes_ok(run, bad_size, good, what, info, errmsg)
        type(run_t), intent(in) :: run
        logical, intent(in) :: bad_size, good
        character(len=*), intent(in) :: what
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = FRIROM_OK
        modes_ok = .false.
        if (.not. open_run(run, what(1:index(what, ':') - 1), info, errmsg)) return
        if (bad_size) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, what//' expected (nm >= 1)')
        else if (.not. good) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, what//': finite shapes, '// &
                            'positive frequencies and damping ratios >= 0 expected')
        end if
        modes_ok = info == FRIROM_OK
    end function modes_ok

    !> Finite positive natural frequencies and finite damping ratios >= 0.
    pure logical function good_modes(w, z)
        real(wp), intent(in) :: w(:), z(:)
        good_modes = all(w > 0.0_wp) .and. all(w <= huge(1.0_wp)) .and. all(z >= 0.0_wp) &
                     .and. all(z <= huge(1.0_wp))
    end function good_modes

    !> The system with the model's real (or, harmonic, per-harmonic) modes of run%m: set
    !> on it, or rebuilt when a selection is set already (the modes come first).
    subroutine apply_modes(run, harmonic, info, errmsg)
        type(run_t), intent(inout) :: run
        logical, intent(in) :: harmonic
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        if (allocated(run%m%keep)) then
            call run_build(run, info, errmsg)
        else if (.not. harmonic) then
            call hbm_set_modes(run%sys, run%m%phi, run%m%wm, run%m%zm, info, errmsg)
        else
            call hbm_set_modes_harmonic(run%sys, run%m%psi, run%m%wh, run%m%zh, info, errmsg)
        end if
    end subroutine apply_modes

    module procedure run_set_free_bodies
        info = FRIROM_OK
        if (.not. open_run(run, 'run_set_free_bodies', info, errmsg)) return
        run%m%free = on
        call run_build(run, info, errmsg)
    end procedure run_set_free_bodies

    module procedure run_set_user_law
        info = FRIROM_OK
        if (.not. open_run(run, 'run_set_user_law', info, errmsg)) return
        run%m%ulaw = ulaw
        if (allocated(run%sys)) run%sys%cs%ulaw = ulaw
    end procedure run_set_user_law

    module procedure run_set_selection
        info = FRIROM_OK
        if (.not. open_run(run, 'run_set_selection', info, errmsg)) return
        if (allocated(run%m%keep)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_set_selection: the run has '// &
                            'a selection already (open a new run)')
            return
        end if
        run%m%keep = keep
        if (present(pair)) run%m%pair = pair
        run%m%orbits = .false.
        if (present(pair) .and. present(orbits)) run%m%orbits = orbits
        if (present(orbtol)) run%m%orbtol = orbtol
        call apply_selection(run, info, errmsg)
        if (info /= 0) then
            deallocate (run%m%keep)
            if (allocated(run%m%pair)) deallocate (run%m%pair)
        end if
    end procedure run_set_selection

    !> The model's selection (run%m keep, pair, orbits) on the system, after its modes;
    !> refused with stability (Hill's method would see only perturbations inside it).
    subroutine apply_selection(run, info, errmsg)
        type(run_t), intent(inout) :: run
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nrep
        integer(ip), allocatable :: omap(:)
        real(wp) :: mis
        info = FRIROM_OK
        if (run%s%stability /= 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: Hill stability '// &
                            'would see only perturbations inside the selection; not with '// &
                            'stability')
            return
        end if
        call hbm_set_selection(run%sys, run%m%keep, info, errmsg, pair=run%m%pair)
        if (info /= 0 .or. .not. (run%m%orbits .and. allocated(run%m%pair))) return
        allocate (omap(max(run%netot, 1)))
        omap = 0
        call hbm_set_orbits(run%sys, run%m%orbtol, nrep, mis, info, errmsg, omap)
        run%orb_nrep = nrep
        run%orb_mis = mis
    end subroutine apply_selection

    !> Settings in their ranges; else FRIROM_ERR_PARAM naming the first one out.
    subroutine check_settings(s, info, errmsg)
        type(run_settings), intent(in) :: s
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        info = FRIROM_OK
        if (s%harmonics < 0 .or. s%harmonics > 200) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'settings.harmonics: expected '// &
                            '0..200')
        else if (s%samples /= 0 .and. s%samples < 2*s%harmonics + 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'settings.samples: expected 0 '// &
                            '(default) or at least 2 harmonics + 1')
        else if (s%max_points < 1 .or. s%max_iter < 1 .or. s%batch < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'settings.max_points, max_iter, '// &
                            'batch: expected >= 1')
        else if (.not. (s%tol_residual > 0.0_wp .and. s%tol_update > 0.0_wp .and. &
                        s%tol_stall >= 0.0_wp .and. s%ds > 0.0_wp .and. s%ds_min > 0.0_wp &
                        .and. s%ds_max >= s%ds_min .and. s%ds <= s%ds_max .and. &
                        s%ds_max <= huge(1.0_wp) .and. s%tol_residual <= huge(1.0_wp) .and. &
                        s%tol_update <= huge(1.0_wp) .and. s%tol_stall <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'settings.tol_residual, '// &
                            'tol_update, ds, ds_min, ds_max: positive and finite, tol_stall '// &
                            '>= 0, ds_min <= ds <= ds_max expected')
        else if (.not. (s%formulation == RUN_CONDENSED .or. s%formulation == RUN_BANDED)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'settings.formulation: expected '// &
                            '1 (condensed) or 2 (banded)')
        end if
    end subroutine check_settings
end submodule frirom_run_setup
