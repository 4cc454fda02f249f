!> Cyclic sectors through the C interface (frirom.h): receptances from modes of their own
!> per harmonic (frirom_run run_set_modes_harmonic: each harmonic's nodal diameter) and
!> the nonlinear mode of one nodal diameter as a travelling wave (run_to_mode, then
!> run_set_nonlinear_mode_cyclic); frirom_run_start_mode and frirom_run_advance_mode
!> (frirom_capi_modes) then drive it as any mode run.
!>
!> Complex arrays are interleaved (re, im) doubles, the layout of C99 double _Complex and
!> C++ std::complex<double>; every array is column-major.
module frirom_capi_cyclic
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, set_status
    use frirom_run, only: run_t, run_to_mode, run_set_modes_harmonic, &
                          run_set_nonlinear_mode_cyclic
    use frirom_capi, only: to_c_string, get_run
    implicit none
    private
    public :: frirom_run_set_modes_harmonic_c, frirom_run_set_nonlinear_mode_cyclic_c

contains

    !> int frirom_run_set_modes_harmonic(frirom_run *run, int nmodes, const double *psi,
    !>                                   const double *omega, const double *zeta,
    !>                                   char *msg, int msglen)
    function frirom_run_set_modes_harmonic_c(run, nmodes, psi, omega, zeta, msg, msglen) &
        result(info) bind(c, name='frirom_run_set_modes_harmonic')
        type(c_ptr), value :: run, msg
        integer(c_int), value :: nmodes, msglen
        complex(c_double_complex), intent(in), optional :: psi(*)
        real(c_double), intent(in), optional :: omega(*), zeta(*)
        integer(c_int) :: info
        character(len=*), parameter :: who = 'frirom_run_set_modes_harmonic'
        type(run_t), pointer :: r
        integer(ip) :: st, n, h1, nm
        character(len=512) :: text
        call get_run(run, who, r, st, text, nmodes, 'nmodes')
        call check_arrays(who, st, text, present(psi), present(omega), present(zeta))
        if (st == FRIROM_OK) then
            n = r%m%ndof
            h1 = r%m%nh + 1
            nm = nmodes
            call check_values(who, psi(:n*nm*h1), omega(:nm*h1), zeta(:nm*h1), st, text)
        end if
        if (st == FRIROM_OK) then
            call run_set_modes_harmonic(r, reshape(psi(:n*nm*h1), [n, nm, h1]), &
                                        reshape(omega(:nm*h1), [nm, h1]), &
                                        reshape(zeta(:nm*h1), [nm, h1]), st, text)
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_modes_harmonic_c

    !> int frirom_run_set_nonlinear_mode_cyclic(frirom_run *run, int nmodes,
    !>                                          const double *q0, double omega0,
    !>                                          const double *psi, const double *omega,
    !>                                          const double *zeta, char *msg, int msglen)
    function frirom_run_set_nonlinear_mode_cyclic_c(run, nmodes, q0, omega0, psi, omega, zeta, &
                                                    msg, msglen) result(info) &
        bind(c, name='frirom_run_set_nonlinear_mode_cyclic')
        type(c_ptr), value :: run, msg
        integer(c_int), value :: nmodes, msglen
        real(c_double), value :: omega0
        complex(c_double_complex), intent(in), optional :: q0(*), psi(*)
        real(c_double), intent(in), optional :: omega(*), zeta(*)
        integer(c_int) :: info
        character(len=*), parameter :: who = 'frirom_run_set_nonlinear_mode_cyclic'
        type(run_t), pointer :: r
        integer(ip) :: st, n, h1, nm
        character(len=512) :: text
        call get_run(run, who, r, st, text, nmodes, 'nmodes')
        if (st == FRIROM_OK) then
            if (.not. present(q0)) call set_status(st, FRIROM_ERR_PARAM, text, who//': q0: NULL')
        end if
        call check_arrays(who, st, text, present(psi), present(omega), present(zeta))
        ! Fortran's .and. need not short-circuit: each check runs only after the last passed
        if (st == FRIROM_OK) then
            if (.not. (omega0 > 0.0_wp .and. omega0 <= huge(1.0_wp))) then
                call set_status(st, FRIROM_ERR_PARAM, text, who//': omega0: a finite '// &
                                'frequency > 0 (rad/s) expected')
            else if (r%m%nh < 1) then
                call set_status(st, FRIROM_ERR_PARAM, text, who//': the run has H = 0 '// &
                                'harmonics; a nonlinear mode needs H >= 1')
            end if
        end if
        if (st == FRIROM_OK) then
            n = r%m%ndof
            h1 = r%m%nh + 1
            nm = nmodes
            call check_values(who, psi(:n*nm*h1), omega(:nm*h1), zeta(:nm*h1), st, text)
        end if
        if (st == FRIROM_OK) then
            if (.not. (all(abs(q0(:nm)) <= huge(1.0_wp)) .and. any(abs(q0(:nm)) > 0.0_wp))) &
                call set_status(st, FRIROM_ERR_PARAM, text, who//': q0: finite modal '// &
                                'coordinates, not all zero, expected')
        end if
        if (st == FRIROM_OK) call run_to_mode(r, .true., st, text)
        if (st == FRIROM_OK) then
            call run_set_nonlinear_mode_cyclic(r, q0(:nm), omega0, &
                                               reshape(psi(:n*nm*h1), [n, nm, h1]), &
                                               reshape(omega(:nm*h1), [nm, h1]), &
                                               reshape(zeta(:nm*h1), [nm, h1]), st, text)
        end if
        call to_c_string(text, msg, msglen)
        info = int(st, c_int)
    end function frirom_run_set_nonlinear_mode_cyclic_c

    !> FRIROM_ERR_PARAM naming the first of psi, omega, zeta that is NULL (st unchanged
    !> when it already holds a failure).
    subroutine check_arrays(who, st, text, has_psi, has_omega, has_zeta)
        character(len=*), intent(in) :: who
        integer(ip), intent(inout) :: st
        character(len=*), intent(inout) :: text
        logical, intent(in) :: has_psi, has_omega, has_zeta
        if (st /= FRIROM_OK) return
        if (.not. has_psi) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': psi: NULL')
        else if (.not. has_omega) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': omega: NULL')
        else if (.not. has_zeta) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': zeta: NULL')
        end if
    end subroutine check_arrays

    !> FRIROM_ERR_PARAM naming the first of psi (finite), omega (finite, > 0), zeta (finite,
    !> >= 0) whose values are out of range.
    subroutine check_values(who, psi, omega, zeta, st, text)
        character(len=*), intent(in) :: who
        complex(c_double_complex), intent(in) :: psi(:)
        real(c_double), intent(in) :: omega(:), zeta(:)
        integer(ip), intent(inout) :: st
        character(len=*), intent(inout) :: text
        if (.not. all(abs(psi) <= huge(1.0_wp))) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': psi: finite shapes expected')
        else if (.not. all(omega > 0.0_wp .and. omega <= huge(1.0_wp))) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': omega: finite natural '// &
                            'frequencies > 0 (rad/s; no rigid-body mode) expected')
        else if (.not. all(zeta >= 0.0_wp .and. zeta <= huge(1.0_wp))) then
            call set_status(st, FRIROM_ERR_PARAM, text, who//': zeta: finite damping '// &
                            'ratios >= 0 expected')
        end if
    end subroutine check_values
end module frirom_capi_cyclic
