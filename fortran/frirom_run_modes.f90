!> Nonlinear modes on the run object of frirom_run (mode RUN_MODE): the extended periodic
!> motion concept of frirom_hbm_epmc driven by the one continuation driver, the parameter
!> log10 of the modal amplitude. run_set_nonlinear_mode gives the run the linear mode it
!> starts from; run_start (cold) then starts from that mode, run_advance continues.
submodule (frirom_run) frirom_run_modes
    use frirom_epmc, only: hbm_epmc_set, hbm_epmc_modal_set
    implicit none

contains

    module procedure run_set_nonlinear_mode
        info = FRIROM_OK
        if (.not. open_run(run, 'run_set_nonlinear_mode', info, errmsg)) return
        if (run%m%mode /= RUN_MODE) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_set_nonlinear_mode: the '// &
                            'run was not opened as a mode run (mode 3)')
            return
        end if
        if (run%m%formulation == RUN_CONDENSED) then
            if (.not. (present(modes) .and. present(wm) .and. present(zm))) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'run_set_nonlinear_mode: '// &
                                'a condensed mode run needs the modes of its receptances')
                return
            end if
            call hbm_epmc_modal_set(run%sys, phi, omega0, modes, wm, zm, run%m%nl, info, &
                                    errmsg)
            if (info /= 0) return
            run%m%mode_modes = modes
            run%m%mode_wm = wm
            run%m%mode_zm = zm
        else
            call hbm_epmc_set(run%sys, phi, omega0, info, errmsg)
            if (info /= 0) return
        end if
        run%m%mode_phi = phi
        run%m%mode_w0 = omega0
        run%ny = run%sys%n
    end procedure run_set_nonlinear_mode

    module procedure run_to_mode
        info = FRIROM_OK
        if (.not. open_run(run, 'run_to_mode', info, errmsg)) return
        associate (m => run%m)
            m%mode = RUN_MODE
            m%formulation = merge(RUN_CONDENSED, RUN_BANDED, condensed)
            m%krylov = 0
            m%sparse = .false.
            m%orbits = .false.
            if (allocated(m%phi)) deallocate (m%phi, m%wm, m%zm)
            if (allocated(m%psi)) deallocate (m%psi, m%wh, m%zh)
            if (allocated(m%keep)) deallocate (m%keep)
            if (allocated(m%pair)) deallocate (m%pair)
            if (allocated(m%mode_phi)) deallocate (m%mode_phi)
            if (allocated(m%mode_modes)) deallocate (m%mode_modes, m%mode_wm, m%mode_zm)
        end associate
        run%s%stability = 0
        run%s%formulation = int(run%m%formulation, c_int)
        if (allocated(run%y)) deallocate (run%y, run%t)
        call run_build(run, info, errmsg)
    end procedure run_to_mode
end submodule frirom_run_modes
