!> frirom_solve (the whole solve for legacy programs) against a closed form: a 2-DoF chain
!> whose Jenkins contact never slips (mu fn0 = 5e8 N against forces < 1e3 N) is linear with
!> stiffness K + kt e1 e1^T, so each FRF point must equal the direct complex solve
!> (K' - w^2 M + i w C) X = F with the damping written out by hand: modal ratios on the
!> chain's modes known in closed form, Rayleigh alpha M + beta K, and a C given as
!> triplets with a duplicate entry. Both formulations, Newton tolerances 1e-12 (a Jacobian
!> kept from an earlier frequency makes steps inexact, so a point is as exact as the
!> tolerance: 3e-10 of the amplitude at the default 1e-8); tolerance 1e-11 of the largest
!> amplitude (5e-14 measured). Also: the points do not depend on batch, max_points ends
!> a run incomplete with a message, and bad damping input is refused naming the field.
program test_solve
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done
    use frirom_status, only: FRIROM_ERR_PARAM
    use frirom_solve, only: frf_settings, frf_result, frf_solve, FRF_CONDENSED, FRF_BANDED, &
                            peak_amplitude
    implicit none
    real(wp), parameter :: k = 1.0e4_wp, kt = 1.0e3_wp, alpha = 0.5_wp, beta = 1.0e-5_wp
    integer(ip), parameter :: kr(4) = [1, 1, 2, 2], kc(4) = [1, 2, 1, 2]
    real(wp), parameter :: kv(4) = [2*k, -k, -k, 2*k]
    integer(ip), parameter :: md(2) = [1, 2], cr(4) = [2, 2, 1, 2], cc(4) = [2, 2, 2, 1]
    real(wp), parameter :: mv(2) = [1.0_wp, 1.0_wp], cv(4) = [0.3_wp, 0.2_wp, 0.1_wp, 0.1_wp]
    integer(ip), parameter :: ginfo(3, 1) = reshape([1, 1, 1], [3, 1]), gr(1) = [1], gc(1) = [1]
    real(wp), parameter :: gv(1) = [1.0_wp], params(3) = [kt, 0.5_wp, 1.0e9_wp]
    real(wp), parameter :: zeta(2) = [0.02_wp, 0.01_wp]
    type(frf_settings) :: s
    type(frf_result) :: res
    real(wp) :: fe(2, 5), c(2, 2), phi(2, 2), w(2), x(5), err, amax
    real(wp), allocatable :: om1(:), am1(:, :)
    complex(wp) :: a(2, 2), f(2), xr(2), det
    integer(ip) :: form, p, j, r
    character(len=40) :: what

    ! modes of K (M = I): [1, 1]/sqrt 2 at sqrt(k), [1, -1]/sqrt 2 at sqrt(3k)
    phi = reshape([1.0_wp, 1.0_wp, 1.0_wp, -1.0_wp], [2, 2])/sqrt(2.0_wp)
    w = [sqrt(k), sqrt(3*k)]
    c = alpha*reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2]) + &
        beta*reshape(kv, [2, 2]) + reshape([0.0_wp, 0.1_wp, 0.1_wp, 0.5_wp], [2, 2])
    do r = 1, 2
        c = c + 2*zeta(r)*w(r)*spread(phi(:, r), 2, 2)*spread(phi(:, r), 1, 2)
    end do
    fe = 0.0_wp
    fe(2, 2) = 10.0_wp          ! 10 cos(w t) + 5 sin(w t) N on DoF 2
    fe(2, 3) = 5.0_wp
    f = cmplx(fe(:, 2), -fe(:, 3), wp)
    s%harmonics = 2
    s%samples = 32
    s%tol_residual = 1.0e-12_wp
    s%tol_update = 1.0e-12_wp
    do form = FRF_CONDENSED, FRF_BANDED
        s%formulation = form
        call frf_solve(2, kr, kc, kv, md, md, mv, cr, cc, cv, alpha, beta, zeta, ginfo, gr, &
                       gc, gv, params, fe, 50.0_wp, 250.0_wp, [1, 2], s, res)
        write (what, '(a,i0)') 'formulation ', form
        call check(res%info == 0 .and. res%complete .and. res%npts > 10, what//': complete')
        call check(res%omega(1) == 50.0_wp .and. res%omega(res%npts) == 250.0_wp, &
                   what//': range')
        err = 0.0_wp
        amax = 0.0_wp
        do p = 1, res%npts
            a = cmplx(reshape(kv, [2, 2]), res%omega(p)*c, wp)
            a(1, 1) = a(1, 1) + kt
            a(1, 1) = a(1, 1) - res%omega(p)**2
            a(2, 2) = a(2, 2) - res%omega(p)**2
            det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
            xr = [a(2, 2)*f(1) - a(1, 2)*f(2), a(1, 1)*f(2) - a(2, 1)*f(1)]/det
            do j = 1, 2
                err = max(err, abs(res%amp(j, p) - abs(xr(j))), &
                          abs(res%xo(j, 2, p) - real(xr(j))), &
                          abs(res%xo(j, 3, p) + aimag(xr(j))), &
                          maxval(abs(res%xo(j, [1, 4, 5], p))))
                amax = max(amax, abs(xr(j)))
            end do
        end do
        call check(err <= 1.0e-11_wp*amax, what//': closed form')
        print '(a,i0,a,i0,a,es9.2)', 'formulation ', form, ': ', res%npts, &
            ' points, max error / max amplitude ', err/amax
    end do
    ! the path does not depend on batch (points per hbm_run call): the arc-length scale
    ! grows after every point inside hbm_run (the amplitude grows 20x from 50 Hz to the
    ! first resonance), and a call that resumes factorises J at its start point as the
    ! uninterrupted run holds it. The same arithmetic split into calls differently, so
    ! the points agree bit for bit (before, the scale grew only between calls: 1 and 1000
    ! gave different points)
    s%batch = 1
    call frf_solve(2, kr, kc, kv, md, md, mv, cr, cc, cv, alpha, beta, zeta, ginfo, gr, gc, &
                   gv, params, fe, 50.0_wp, 250.0_wp, [1, 2], s, res)
    allocate (om1, source=res%omega)
    allocate (am1, source=res%amp)
    s%batch = 1000
    call frf_solve(2, kr, kc, kv, md, md, mv, cr, cc, cv, alpha, beta, zeta, ginfo, gr, gc, &
                   gv, params, fe, 50.0_wp, 250.0_wp, [1, 2], s, res)
    print '(a,i0,a,i0,a)', 'batch 1: ', size(om1), ' points, batch 1000: ', res%npts, ' points'
    call check(res%complete .and. res%npts == size(om1), 'batch 1 and 1000: as many points')
    if (res%npts == size(om1)) call check(all(res%omega == om1) .and. all(res%amp == am1), &
                                          'batch 1 and 1000: the same points')
    s%batch = 10
    ! max_points: an incomplete run keeps its points and says why
    s%max_points = 3
    call frf_solve(2, kr, kc, kv, md, md, mv, cr, cc, cv, alpha, beta, zeta, ginfo, gr, gc, &
                   gv, params, fe, 50.0_wp, 250.0_wp, [2], s, res)
    call check(res%info == 0 .and. .not. res%complete .and. res%npts == 3 .and. &
               index(res%message, 'max_points') > 0, 'max_points stops the run')
    ! bad input: named, no point
    call frf_solve(2, kr, kc, kv, md, md, mv, cr, cc, cv, alpha, beta, [1.5_wp], ginfo, gr, &
                   gc, gv, params, fe, 50.0_wp, 250.0_wp, [2], s, res)
    call check(res%info == FRIROM_ERR_PARAM .and. res%npts == 0 .and. &
               index(res%message, 'zeta') > 0, 'zeta >= 1 refused')
    ! peak of x(t) = 1 + cos t + 0.5 sin 2t: x' = 0 at sin t = (1 - sqrt 33)/8 ... checked
    ! against a fine sampling (10^5 points, error < 1e-9)
    x = [1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.5_wp]
    amax = 0.0_wp
    do p = 0, 99999
        amax = max(amax, abs(1 + cos(6.283185307179586_wp*p/1e5_wp) + &
                             0.5_wp*sin(2*6.283185307179586_wp*p/1e5_wp)))
    end do
    call check(peak_amplitude(x) >= amax - 1e-9_wp .and. peak_amplitude(x) <= amax + 1e-8_wp, &
               'peak_amplitude')
    call check_done('test_solve')
end program test_solve
