!> frirom_hbm: residual, Jacobian and dR/dlam of both formulations against central finite
!> differences, and agreement of the two formulations' solutions, on a 4-DoF chain with a
!> cubic spring to ground and a cubic spring between two masses (Duffing-type, so the AFT
!> force is smooth and finite differences are accurate to ~1e-8).
program test_hbm
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done, fixed_seed
    use frirom_newton, only: cont_options, newton_correct
    use frirom_hbm, only: hbm_system, hbm_condensed, hbm_full, hbm_setup, hbm_set_modes, &
                          hbm_set_modes_harmonic, hbm_set_selection, hbm_sel_expand, &
                          hbm_sel_reduce, hbm_set_orbits, cond_leak
    implicit none
    integer(ip), parameter :: ndof = 4, nh = 3, nc = 2*nh + 1
    type(hbm_condensed) :: sc, scl
    type(hbm_full), target :: sf
    type(hbm_full) :: sfl, sbad, sfn
    type(hbm_condensed) :: scn, scm, sch, sct, sctl, sctn, sctm, scd, scp
    integer(ip) :: keep(3, 0:nh), pair(3, 0:nh)
    real(wp) :: zp(3*nc - 4), zq(3*nc - 4), yfp(3*nc)
    type(hbm_full) :: sfd
    complex(wp) :: psi(ndof, ndof, 0:nh)
    real(wp) :: yr(3*nc), r1(3*nc), r2(3*nc), rl1(3*nc), rl2(3*nc), rr1, rr2
    integer(ip) :: h
    real(wp) :: kd(ndof, ndof), md(ndof, ndof), wev(ndof), work(64)
    integer(ip) :: k
    integer(ip) :: kp(ndof + 1), ki(10), mp(ndof + 1), mi(ndof), cp(ndof + 1), ci(10)
    real(wp) :: kx(10), mx(ndof), cx(10), fe0(ndof, nc), fe1(ndof, nc)
    integer(ip) :: perm(ndof), nl(3), ginfo(3, 1), gp(3), gi(3), outd(ndof)
    real(wp) :: gx(3), params(4), w0(1)
    integer(ip) :: info, i
    character(len=512) :: msg
    real(wp) :: err
    ! K: chain 1-2-3-4 with ground at 1; stored as CSR
    kp = [1, 3, 6, 9, 11]
    ki = [1, 2, 1, 2, 3, 2, 3, 4, 3, 4]
    kx = [2.0_wp, -1.0_wp, -1.0_wp, 2.0_wp, -1.0_wp, -1.0_wp, 2.0_wp, -1.0_wp, -1.0_wp, &
          1.0_wp]
    mp = [1, 2, 3, 4, 5]
    mi = [1, 2, 3, 4]
    mx = [1.0_wp, 0.5_wp, 1.5_wp, 1.0_wp]
    cp = kp
    ci = ki
    cx = 0.02_wp*kx
    perm = [3, 1, 4, 2]
    nl = [2, 3, 4]
    fe0 = 0.0_wp
    fe0(1, 2) = 0.3_wp
    fe0(1, 3) = -0.1_wp
    fe0(2, 1) = 0.05_wp
    fe1 = 0.0_wp
    fe1(4, 2) = 0.2_wp
    ! two cubic elements: DoF 4 to ground, DoF 2 - DoF 3
    ginfo(:, 1) = [4, 2, 1]
    gp = [1, 2, 4]
    gi = [4, 2, 3]
    gx = [1.0_wp, 1.0_wp, -1.0_wp]
    params = [0.3_wp, 2.0_wp, 0.1_wp, 1.5_wp]
    w0 = 0.0_wp
    outd = [1, 2, 3, 4]
    msg = ''
    call hbm_setup(sc, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call check(info == 0, 'setup condensed: '//trim(msg))
    call hbm_setup(sf, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call check(info == 0, 'setup full: '//trim(msg))
    call fd_check(sc, 'condensed')
    call fd_check(sf, 'full')
    call agree(sc, 'condensed')
    ! unknowns in contact coordinates u = G x (2 per harmonic instead of 3 DoFs)
    call hbm_setup(sct, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg, &
                   contact_coords=.true.)
    call check(info == 0 .and. sct%n == 2*nc, 'setup condensed in G x: '//trim(msg))
    call fd_check(sct, 'condensed G x')
    call agree(sct, 'condensed G x')
    ! two cubic elements that each read all three nl DoFs (an interface reduced to a few
    ! generalised DoFs): dF/dU summed densely before the product with R_h
    call hbm_setup(scd, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, [1, 4, 7], [2, 3, 4, 2, 3, 4], &
                   [1.0_wp, -0.5_wp, 0.3_wp, 0.2_wp, 0.7_wp, -1.0_wp], params, w0, outd, info, msg)
    call check(info == 0, 'setup condensed, dense dF/dU: '//trim(msg))
    call fd_check(scd, 'condensed dense dF/dU')
    call hbm_setup(sfd, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, [1, 4, 7], [2, 3, 4, 2, 3, 4], &
                   [1.0_wp, -0.5_wp, 0.3_wp, 0.2_wp, 0.7_wp, -1.0_wp], params, w0, outd, info, msg)
    call agree(scd, 'condensed dense dF/dU', sfd)
    ! load mode: same checks with lam = load factor
    call hbm_setup(scl, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 2, 0.9_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call check(info == 0, 'setup condensed load')
    call fd_check(scl, 'condensed load')
    call hbm_setup(sctl, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 2, 0.9_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg, &
                   contact_coords=.true.)
    call fd_check(sctl, 'condensed G x load')
    call hbm_setup(sfl, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 2, 0.9_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call fd_check(sfl, 'full load')
    ! a 1-D normal-load friction element (2 directions) between DoF 3 (tangential) and
    ! DoF 4 (normal), kept closed by its preload: piecewise smooth, so the finite
    ! differences are only checked where no sample changes state (small perturbation)
    call hbm_setup(scn, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, reshape([2, 1, 2], [3, 1]), [1, 2, 3], [3, 4], &
                   [1.0_wp, 1.0_wp], [0.5_wp, 1.0_wp, 0.3_wp, 0.2_wp], [0.0_wp], outd, info, msg)
    call check(info == 0, 'setup normal1d: '//trim(msg))
    call fd_check(scn, 'condensed normal1d')
    call hbm_setup(sctn, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, reshape([2, 1, 2], [3, 1]), [1, 2, 3], [3, 4], &
                   [1.0_wp, 1.0_wp], [0.5_wp, 1.0_wp, 0.3_wp, 0.2_wp], [0.0_wp], outd, info, &
                   msg, contact_coords=.true.)
    call fd_check(sctn, 'condensed G x normal1d')
    call hbm_setup(sfn, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, reshape([2, 1, 2], [3, 1]), [1, 2, 3], [3, 4], &
                   [1.0_wp, 1.0_wp], [0.5_wp, 1.0_wp, 0.3_wp, 0.2_wp], [0.0_wp], outd, info, msg)
    call fd_check(sfn, 'full normal1d')
    ! modal superposition receptances (all 4 modes, ratios 2 %): Jacobian and dR/dw
    kd = 0.0_wp
    md = 0.0_wp
    do i = 1, ndof
        md(i, i) = mx(i)
        do k = kp(i), kp(i + 1) - 1
            kd(i, ki(k)) = kx(k)
        end do
    end do
    call dsygv(1, 'V', 'U', ndof, kd, ndof, md, ndof, wev, work, 64, info)
    call check(info == 0, 'dsygv')
    call hbm_setup(scm, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call hbm_set_modes(scm, kd, sqrt(wev), [(0.02_wp, i = 1, ndof)], info, msg)
    call check(info == 0, 'set modes: '//trim(msg))
    call fd_check(scm, 'condensed modal')
    ! all modes, contact coordinates: the modal route's J, dR/dw and outputs
    call hbm_setup(sctm, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg, &
                   contact_coords=.true.)
    call hbm_set_modes(sctm, kd, sqrt(wev), [(0.02_wp, i = 1, ndof)], info, msg)
    call check(info == 0, 'set modes G x: '//trim(msg))
    call fd_check(sctm, 'condensed G x modal')
    ! modes per harmonic (hbm_set_modes_harmonic, the cyclic-sector path): the real shapes
    ! times a phase of their own for every mode and harmonic give the same receptances
    ! Psi g Psi^H, hence the same residual and dR/dw as the real modes to rounding
    do h = 0, nh
        do i = 1, ndof
            psi(:, i, h) = kd(:, i)*exp(cmplx(0.0_wp, 0.7_wp*i + 1.3_wp*h, wp))
        end do
    end do
    call hbm_setup(sch, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call hbm_set_modes_harmonic(sch, psi, spread(sqrt(wev), 2, nh + 1), &
                                spread([(0.02_wp, i = 1, ndof)], 2, nh + 1), info, msg)
    call check(info == 0, 'set harmonic modes: '//trim(msg))
    call random_number(yr)
    yr = 0.2_wp*(yr - 0.5_wp)
    call scm%eval(yr, 0.9_wp, r1, rr1, .false., rl1, info, msg)
    call sch%eval(yr, 0.9_wp, r2, rr2, .false., rl2, info, msg)
    err = max(maxval(abs(r1 - r2))/rr1, maxval(abs(rl1 - rl2))/maxval(abs(rl1)))
    print '(a, es9.2)', 'harmonic modes vs real modes: residual and dR/dw differ by ', err
    call check(err < 1.0e-13_wp, 'harmonic modes reproduce the real modal receptances')
    call fd_check(sch, 'condensed harmonic modes')
    ! a mode of zero frequency is refused with a message
    call hbm_set_modes_harmonic(sch, psi, 0.0_wp*spread(sqrt(wev), 2, nh + 1), &
                                spread([(0.02_wp, i = 1, ndof)], 2, nh + 1), info, msg)
    call check(info /= 0 .and. index(msg, 'omega > 0') > 0, 'zero frequency reported')
    ! a selection with pairs (hbm_set_selection's pair): keep everything, tie harmonic 1
    ! of nonlinear DoF 1 to DoF 2 (s = +1) and harmonic 2 of DoF 3 to DoF 1 (s = -1): the
    ! Jacobian T^T J T of the 4 fewer unknowns against finite differences of T^T R(T z)
    call hbm_setup(scp, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    keep = 1
    pair = 0
    pair(2, 1) = 2
    call hbm_set_selection(scp, keep, info, msg, pair=pair)
    call check(info /= 0 .and. index(msg, 'no other coordinate') > 0 .and. scp%n == 3*nc &
               .and. .not. allocated(scp%sel), 'a failed selection leaves the system as it was')
    pair = 0
    pair(1, 1) = 2
    pair(3, 2) = -1
    call hbm_set_selection(scp, keep, info, msg, pair=pair)
    call check(info == 0 .and. scp%n == 3*nc - 4, 'selection with two pairs: '//trim(msg))
    pair(1, 0) = 2
    call hbm_set_selection(scp, keep, info, msg, pair=pair)
    call check(info /= 0 .and. index(msg, 'harmonic 0') > 0 .and. scp%n == 3*nc - 4, &
               'a failed selection keeps the pairs set before')
    call fd_check(scp, 'condensed paired')
    ! the same on the element loops' path (sparse rows: kc T from the full assembly)
    call check(scp%cs%grp(1)%asm_mode == 2, 'the chain takes the dense rows')
    scp%cs%grp(1)%asm_mode = 1
    call fd_check(scp, 'condensed paired, element loops')
    ! T^T T = I, and T z has the pairs' relations (full layout j + 3 (c - 1), c = 2 h
    ! the cosine): y(k, sin) = s y(j, cos), y(k, cos) = -s y(j, sin)
    call random_number(zp)
    call hbm_sel_expand(scp, zp, yfp)
    call hbm_sel_reduce(scp, yfp, zq)
    call check(maxval(abs(zq - zp)) < 1.0e-15_wp, 'pairs: T^T T = I')
    call check(maxval(abs([yfp(2 + 3*2) - yfp(1 + 3*1), yfp(2 + 3*1) + yfp(1 + 3*2), &
                           yfp(1 + 3*4) + yfp(3 + 3*3), yfp(1 + 3*3) - yfp(3 + 3*4)])) &
               < 1.0e-15_wp, 'pairs: the relations of T z')
    ! bad input is reported, not crashed on
    perm = [1, 1, 2, 3]
    call hbm_setup(sbad, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                   fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
    call check(info /= 0 .and. index(msg, 'perm') > 0, 'bad perm reported')
    perm = [3, 1, 4, 2]
    call roundoff_selection()
    call orbits_check()
    call check_done('test_hbm')

contains

    !> hbm_roundoff under a selection (hbm_set_selection): harmonic 0 is the kept rows of
    !> harmonic 0 only, tested against rref; the rest against rref_dyn. Kept rows: none of
    !> harmonic 0 and DoF 1 at harmonic 1 (n = 2 unknowns, fewer than nnl = 3: the full
    !> layout's split at nnl would read past r), then DoF 1 at harmonic 0 and DoFs 1, 2 at
    !> harmonic 1 (n = 5: the split at nnl would count two harmonic-1 rows as static).
    !> rref = 1, rref_dyn = 1e-6, round-off 100 eps = 2.2e-14: harmonic-1 rows of 1e-15
    !> (round-off of the static scale, 4.5e-7 of the dynamic one's) are no round-off.
    subroutine roundoff_selection()
        type(hbm_condensed) :: s
        integer(ip) :: keep(3, 0:nh)
        real(wp), parameter :: d = 1.0e-15_wp
        call hbm_setup(s, nh, 32, ndof, kp, ki, kx, mp, mi, mx, cp, ci, cx, perm, nl, fe0, &
                       fe1, 1, 0.0_wp, ginfo, gp, gi, gx, params, w0, outd, info, msg)
        call check(info == 0, 'setup for the selection: '//trim(msg))
        keep = 0
        keep(1, 1) = 1
        call hbm_set_selection(s, keep, info, msg)
        call check(info == 0 .and. s%n == 2, 'selection of 2 unknowns: '//trim(msg))
        s%rref_dyn = 1.0e-6_wp
        call check(.not. s%roundoff([d, d], 1.0_wp), &
                   'n < nnl: harmonic-1 rows of 1e-15 against rref_dyn, not round-off')
        call check(s%roundoff([1.0e-22_wp, 1.0e-22_wp], 1.0_wp), &
                   'n < nnl: harmonic-1 rows of 1e-22 are round-off')
        keep(1, 0) = 1
        keep(2, 1) = 1
        call hbm_set_selection(s, keep, info, msg)
        call check(info == 0 .and. s%n == 5, 'selection of 5 unknowns: '//trim(msg))
        s%rref_dyn = 1.0e-6_wp
        call check(.not. s%roundoff([0.0_wp, d, d, 0.0_wp, 0.0_wp], 1.0_wp), &
                   'n > nnl: harmonic-1 rows of 1e-15 next to the static one, not round-off')
        call check(s%roundoff([1.0e-15_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp), &
                   'n > nnl: a static row of 1e-15 against rref is round-off')
    end subroutine roundoff_selection

    !> J^-1 (R(y + e v) - R(y - e v)) / 2e must give v back, for v = each unit vector, at a
    !> random y; and rlam must match the central difference in lam. Tolerance 1e-6:
    !> central differences of a smooth (cubic) residual with e = 1e-6 relative are
    !> accurate to ~1e-9; 1e-6 leaves room for the conditioning of J.
    subroutine fd_check(s, name)
        class(hbm_system), intent(inout) :: s
        character(len=*), intent(in) :: name
        real(wp), allocatable :: y(:), r(:), rp(:), rm(:), rl(:), dum(:), b(:, :)
        real(wp) :: lam, rref, e, errj, errl
        integer(ip) :: j, n
        n = s%n
        allocate (y(n), r(n), rp(n), rm(n), rl(n), dum(n), b(n, 1))
        call fixed_seed(2026)
        call random_number(y)
        y = 0.2_wp*(y - 0.5_wp)
        lam = 0.9_wp
        e = 1.0e-6_wp
        errj = 0.0_wp
        call s%eval(y, lam, r, rref, .true., rl, info, msg)
        call check(info == 0, name//' eval: '//trim(msg))
        do j = 1, n
            y(j) = y(j) + e
            call s%eval(y, lam, rp, rref, .false., dum, info, msg)
            y(j) = y(j) - 2*e
            call s%eval(y, lam, rm, rref, .false., dum, info, msg)
            y(j) = y(j) + e
            b(:, 1) = (rp - rm)/(2*e)
            ! refactor at y (evals above did not touch the factorisation)
            call s%solve(b, info, msg)
            b(j, 1) = b(j, 1) - 1.0_wp
            errj = max(errj, maxval(abs(b(:, 1))))
        end do
        call s%eval(y, lam + e, rp, rref, .false., dum, info, msg)
        call s%eval(y, lam - e, rm, rref, .false., dum, info, msg)
        errl = maxval(abs((rp - rm)/(2*e) - rl))/max(maxval(abs(rl)), 1.0e-12_wp)
        print '(a,a,es10.2,a,es10.2)', name, ': max |J^-1 J_fd - I| =', errj, &
            ', rel err dR/dlam =', errl
        call check(errj < 1.0e-6_wp, name//' Jacobian vs finite differences')
        call check(errl < 1.0e-6_wp, name//' dR/dlam vs finite differences')
    end subroutine fd_check

    !> hbm_set_orbits on a ring of 5 cubic springs, u_s = cos(2 pi s/5) q_c + sin(2 pi s/5)
    !> q_s, under its EO 1 travelling wave (harmonic 1 of q_c and q_s kept, paired s = +1):
    !> the elements are one orbit (one AFT), and with 32 samples the cubic's harmonics up to
    !> 9 are sampled without aliasing, so the orbits' residual, dR/dlam and Jacobian equal
    !> those of every element to round-off; the Jacobian also against finite differences.
    !> One element's k3 changed: it is an orbit of its own and the rest still agree.
    subroutine orbits_check()
        integer(ip), parameter :: ne = 5
        type(hbm_condensed), target :: sos(2), sas(2), sms(2)
        type(hbm_condensed), pointer :: so, sa, sm
        type(hbm_condensed) :: smo, smu
        real(wp) :: phi2(2, 2), xou(2, nc)
        real(wp), allocatable :: yfu(:)
        integer(ip) :: map(ne), map2(ne)
        integer(ip) :: rkp(3), rki(2), rperm(2), rnl(2), rgi(2*ne), rgp(ne + 1), rginfo(3, 1)
        integer(ip) :: rkeep(2, 0:nh), rpair(2, 0:nh), nrep, s, n
        real(wp) :: rkx(2), rmx(2), rcx(2), rfe0(2, nc), rfe1(2, nc), rgx(2*ne), &
                    rpar(2*ne), rw0(1), mis, xo(2, nc)
        real(wp), allocatable :: y(:), ro(:), ra(:), lo(:), la(:)
        real(wp) :: rro, rra
        rkp = [1, 2, 3]
        rki = [1, 2]
        rkx = [1.0_wp, 1.0_wp]
        rmx = [1.0_wp, 1.0_wp]
        rcx = 0.02_wp*rkx
        rperm = [1, 2]
        rnl = [1, 2]
        rfe0 = 0.0_wp
        rfe0(1, 2) = 0.3_wp            ! q_c cos, q_s sin: the wave cos(w t - 2 pi s/5)
        rfe0(2, 3) = 0.3_wp
        rfe1 = 0.0_wp
        rginfo(:, 1) = [4, ne, 1]
        do s = 0, ne - 1
            rgp(s + 1) = 2*s + 1
            rgi(2*s + 1:2*s + 2) = [1, 2]
            rgx(2*s + 1:2*s + 2) = [cos(2*acos(-1.0_wp)*s/ne), sin(2*acos(-1.0_wp)*s/ne)]
            rpar(2*s + 1:2*s + 2) = [0.3_wp, 2.0_wp]
        end do
        rgp(ne + 1) = 2*ne + 1
        rw0 = 0.0_wp
        rkeep = 0
        rkeep(:, 1) = 1
        rpair = 0
        rpair(1, 1) = 2
        do k = 1, 2
            if (k == 2) rpar(2*3 + 2) = 3.0_wp          ! element 4's k3
            so => sos(k)
            sa => sas(k)
            sm => sms(k)
            call hbm_setup(so, nh, 32, 2, rkp, rki, rkx, rkp, rki, rmx, rkp, rki, rcx, rperm, &
                           rnl, rfe0, rfe1, 1, 0.0_wp, rginfo, rgp, rgi, rgx, rpar, rw0, rnl, &
                           info, msg)
            call check(info == 0, 'ring setup: '//trim(msg))
            call hbm_setup(sa, nh, 32, 2, rkp, rki, rkx, rkp, rki, rmx, rkp, rki, rcx, rperm, &
                           rnl, rfe0, rfe1, 1, 0.0_wp, rginfo, rgp, rgi, rgx, rpar, rw0, rnl, &
                           info, msg)
            call hbm_set_selection(so, rkeep, info, msg, pair=rpair)
            call hbm_set_selection(sa, rkeep, info, msg, pair=rpair)
            call check(info == 0 .and. so%n == 2, 'ring: pairs: '//trim(msg))
            map = 0
            call hbm_set_orbits(so, 1.0e-9_wp, nrep, mis, info, msg, map)
            print '(a, i0, a, i0, a, es9.2)', 'ring orbits: AFT on ', nrep, ' of ', ne, &
                ' elements, misfit ', mis
            call check(info == 0 .and. nrep == k .and. so%orbits .and. mis < 1.0e-14_wp, &
                       'ring: the orbits found')
            call check(all(map == merge([1, 1, 1, 4, 1], [1, 1, 1, 1, 1], k == 2)), &
                       'ring: the orbit map')
            ! a later call of the run takes the map back; a map that cannot be one (a
            ! representative after its element) is searched again
            call hbm_setup(sm, nh, 32, 2, rkp, rki, rkx, rkp, rki, rmx, rkp, rki, rcx, rperm, &
                           rnl, rfe0, rfe1, 1, 0.0_wp, rginfo, rgp, rgi, rgx, rpar, rw0, rnl, &
                           info, msg)
            call hbm_set_selection(sm, rkeep, info, msg, pair=rpair)
            map2 = [2, 2, 2, 2, 2]
            call hbm_set_orbits(sm, 1.0e-9_wp, nrep, mis, info, msg, map2)
            call check(info == 0 .and. nrep == k .and. all(map2 == map), &
                       'ring: a bad map is searched again')
            call hbm_set_orbits(sm, 1.0e-9_wp, nrep, mis, info, msg, map2)
            call check(info == 0 .and. nrep == k .and. mis == 0.0_wp .and. &
                       all(sm%orb(1)%mult == so%orb(1)%mult) .and. &
                       all(sm%orb(1)%gz == so%orb(1)%gz), 'ring: the map taken back')
            n = so%n
            allocate (y(n), ro(n), ra(n), lo(n), la(n))
            y = [0.8_wp, -0.3_wp]
            call so%eval(y, 0.9_wp, ro, rro, .true., lo, info, msg)
            call sa%eval(y, 0.9_wp, ra, rra, .true., la, info, msg)
            call check(maxval(abs(ro - ra)) < 1.0e-13_wp*rra .and. &
                       maxval(abs(lo - la)) < 1.0e-13_wp*maxval(abs(la)) .and. &
                       maxval(abs(so%jm - sa%jm)) < 1.0e-13_wp*maxval(abs(sa%jm)), &
                       'ring: the orbits give every element''s residual and Jacobian')
            ! the points' check, every element at y: the orbits' forces agree; the mistuned
            ! ring leaks off the wave (the selection's own leak, not the orbits')
            call so%outputs(y, 0.9_wp, xo, info, msg)
            call check(info == 0 .and. so%orb_leak < 1.0e-14_wp, &
                       'ring: the orbits'' leak at round-off')
            call check(merge(cond_leak(so) < 1.0e-12_wp, cond_leak(so) > 1.0e-3_wp, k == 1), &
                       'ring: the selection leaks when mistuned')
            ! orbits that no longer stand for their elements (the representative's k3 in
            ! the orbits' copy changed): the points' leak says so
            so%orb(1)%params(2, 1) = 1.1_wp*so%orb(1)%params(2, 1)
            call so%outputs(y, 0.9_wp, xo, info, msg)
            call check(so%orb_leak > 1.0e-3_wp .and. cond_leak(so) >= so%orb_leak, &
                       'ring: the orbits'' leak when they differ from every element')
            call fd_check(so, 'condensed paired, orbits')
            deallocate (y, ro, ra, lo, la)
        end do
        ! the outputs of a modal ring (phi = I, omega 1, zeta 0.01: the same receptances),
        ! selected (its forces off the kept rows at round-off: A^T fc over the kept rows)
        ! against the ring unselected at the same point (every row)
        rpar(2*3 + 2) = 2.0_wp
        call hbm_setup(smo, nh, 32, 2, rkp, rki, rkx, rkp, rki, rmx, rkp, rki, rcx, rperm, &
                       rnl, rfe0, rfe1, 1, 0.0_wp, rginfo, rgp, rgi, rgx, rpar, rw0, rnl, &
                       info, msg)
        call hbm_setup(smu, nh, 32, 2, rkp, rki, rkx, rkp, rki, rmx, rkp, rki, rcx, rperm, &
                       rnl, rfe0, rfe1, 1, 0.0_wp, rginfo, rgp, rgi, rgx, rpar, rw0, rnl, &
                       info, msg)
        phi2 = reshape([1.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [2, 2])
        call hbm_set_modes(smo, phi2, [1.0_wp, 1.0_wp], [0.01_wp, 0.01_wp], info, msg)
        call hbm_set_modes(smu, phi2, [1.0_wp, 1.0_wp], [0.01_wp, 0.01_wp], info, msg)
        call hbm_set_selection(smo, rkeep, info, msg, pair=rpair)
        call hbm_set_orbits(smo, 1.0e-9_wp, nrep, mis, info, msg)
        allocate (y(smo%n), ro(smo%n), lo(smo%n), ra(smu%n), la(smu%n), yfu(smu%n))
        y = [0.8_wp, -0.3_wp]
        call hbm_sel_expand(smo, y, yfu)
        call smo%eval(y, 0.9_wp, ro, rro, .false., lo, info, msg)
        call smo%outputs(y, 0.9_wp, xo, info, msg)
        call smu%eval(yfu, 0.9_wp, ra, rra, .false., la, info, msg)
        call smu%outputs(yfu, 0.9_wp, xou, info, msg)
        print '(a, es9.2)', 'ring outputs, selected vs every row: ', &
            maxval(abs(xo - xou))/maxval(abs(xou))
        call check(info == 0 .and. maxval(abs(xo - xou)) < 1.0e-13_wp*maxval(abs(xou)), &
                   'ring: the selected outputs over the kept rows')
    end subroutine orbits_check

    !> Both formulations solved at the same frequency give the same output harmonics.
    subroutine agree(sc, name, sfo)
        class(hbm_system), intent(inout) :: sc
        character(len=*), intent(in) :: name
        type(hbm_full), intent(inout), optional, target :: sfo  !! default: sf
        type(cont_options) :: o
        type(hbm_full), pointer :: pf
        real(wp), allocatable :: yc(:), yf(:), z(:)
        real(wp) :: lc, lf, xc(ndof, nc), xf(ndof, nc)
        integer(ip) :: it
        logical :: hf
        pf => sf
        if (present(sfo)) pf => sfo
        o%tol_r = 1.0e-13_wp
        o%tol_x = 1.0e-12_wp
        o%yscale = 1.0e-3_wp
        allocate (yc(sc%n), yf(pf%n))
        yc = 0.0_wp
        yf = 0.0_wp
        lc = 0.9_wp
        lf = 0.9_wp
        allocate (z(sc%n))
        z = 0.0_wp
        hf = .false.
        call newton_correct(sc, yc, lc, yc, lc, z, 1.0_wp, o, it, info, msg, hf)
        call check(info == 0, name//' Newton: '//trim(msg))
        deallocate (z)
        allocate (z(pf%n))
        z = 0.0_wp
        hf = .false.
        call newton_correct(pf, yf, lf, yf, lf, z, 1.0_wp, o, it, info, msg, hf)
        call check(info == 0, 'full Newton: '//trim(msg))
        call sc%outputs(yc, lc, xc, info, msg)
        call pf%outputs(yf, lf, xf, info, msg)
        err = maxval(abs(xc - xf))/maxval(abs(xf))
        print '(a,a,es10.2,a,es10.2)', name, ' vs full: max rel diff', err, &
            '  |x| =', maxval(abs(xf))
        call check(err < 1.0e-10_wp, name//' and full formulations agree')
    end subroutine agree
end program test_hbm
