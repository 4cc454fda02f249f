!> Nonlinear modes on the run object of frirom_run (mode RUN_MODE): the extended periodic
!> motion concept of frirom_hbm_epmc driven by the one continuation driver, the parameter
!> log10 of the modal amplitude. run_set_nonlinear_mode gives the run the linear mode it
!> starts from; run_start (cold) then starts from that mode, run_advance continues.
submodule (frirom_run) frirom_run_modes
    use frirom_hbm, only: hbm_epmc_set
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
        call hbm_epmc_set(run%sys, phi, omega0, info, errmsg)
        if (info /= 0) return
        run%m%mode_phi = phi
        run%m%mode_w0 = omega0
        run%ny = run%sys%n
    end procedure run_set_nonlinear_mode
end submodule frirom_run_modes
