!> The EPMC of a cyclic sector (a nonlinear mode of a tuned rotor at one nodal diameter, as
!> a travelling wave): hbm_epmc_modal with modes of its own per harmonic. Harmonic h of
!> the travelling wave of nodal diameter k lives on nodal diameter k_h = +-h k mod N, so
!> its receptance is that of k_h's modes (Psi_h complex, the next sector's contact DoFs
!> phase-shifted by exp(i k_h 2 pi / N), as for a forced response under engine order k);
!> the residual, its Jacobian and the outputs are hbm_epmc_modal's (frirom_hbm_epmc_modal).
submodule (frirom_epmc) frirom_hbm_epmc_cyclic
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, set_status, failed
    implicit none

contains

    module procedure hbm_epmc_cyclic_set
        integer(ip) :: nd, nm, nnl, nh
        complex(wp), allocatable :: u1(:)
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_epmc_modal)
            nd = sys%ndof
            nm = size(psi, 2)
            nnl = size(nl)
            nh = sys%nh
            if (failed(size(psi, 1) /= nd .or. ubound(psi, 3) /= nh .or. nm < 1 .or. &
                       size(q0) /= nm .or. any(shape(wh) /= [nm, nh + 1]) .or. &
                       any(shape(zh) /= [nm, nh + 1]) .or. nnl < 1, info, FRIROM_ERR_SIZE, &
                       errmsg, 'nonlinear mode (cyclic): psi (ndof, nm, H+1), omega, zeta '// &
                       '(nm, H+1), q0 (nm) and the contact DoFs expected')) return
            call epmc_modal_base(sys, nm, nl, w0, info, errmsg)
            if (info /= FRIROM_OK) return
            if (failed(.not. (all(wh > 0.0_wp) .and. all(zh >= 0.0_wp) .and. w0 > 0.0_wp &
                       .and. all(abs(psi) <= huge(1.0_wp)) .and. all(abs(q0) <= huge(1.0_wp)) &
                       .and. all(abs(wh) + abs(zh) <= huge(1.0_wp)) .and. w0 <= huge(1.0_wp)), &
                       info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode (cyclic): finite '// &
                       'modes, omega > 0 (no rigid-body mode), zeta >= 0 and omega0 > 0')) return
            if (failed(.not. (norm2(abs(q0)) > 0.0_wp), info, FRIROM_ERR_PARAM, errmsg, &
                       'nonlinear mode (cyclic): the linear mode q0 is zero')) return
            if (allocated(sys%phn)) deallocate (sys%phn, sys%pho, sys%wr, sys%zr)
            allocate (sys%phn(nnl, nm, 0:nh), sys%pho(size(sys%outdofs), nm, 0:nh), &
                      sys%wr(nm, 0:nh), sys%zr(nm, 0:nh))
            sys%phn = psi(nl, :, :)
            sys%pho = psi(sys%outdofs, :, :)
            sys%wr = wh
            sys%zr = zh
            sys%cph = q0/norm2(abs(q0))
            sys%qst = matmul(conjg(transpose(psi(:, :, 0))), &
                             cmplx(sys%fe0(:, 1), 0.0_wp, wp))
            u1 = matmul(psi(nl, :, 1), sys%cph)
            sys%wn = max(norm2(abs(u1)), tiny(1.0_wp))
            sys%nf = nnl*sys%nc
            sys%n = sys%nf + 2
            if (allocated(sys%jd)) deallocate (sys%jd, sys%ipiv, sys%jp, sys%fl)
            allocate (sys%jd(sys%n, sys%n), sys%ipiv(sys%n), sys%jp(sys%nf, sys%nf), &
                      sys%fl(nnl, sys%nc))
            ! the start: the linear travelling wave (z = a - i b), xi = q0^H diag(2 zeta w) q0
            if (allocated(sys%y0)) deallocate (sys%y0)
            allocate (sys%y0(sys%n))
            sys%y0 = 0.0_wp
            sys%y0(nnl + 1:2*nnl) = real(u1)
            sys%y0(2*nnl + 1:3*nnl) = -aimag(u1)
            sys%y0(sys%nf + 1) = 1.0_wp
            sys%y0(sys%nf + 2) = sum(abs(sys%cph)**2*2.0_wp*zh(:, 1)*wh(:, 1))/w0
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'nonlinear mode (cyclic): not a '// &
                            'condensed mode run')
        end select
    end procedure hbm_epmc_cyclic_set
end submodule frirom_hbm_epmc_cyclic
