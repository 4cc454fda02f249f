!> One AFT per orbit of contact elements on a tuned rotor's travelling wave (frirom_hbm
!> orbit_group). On a selection with pairs every unknown vector z is one travelling wave, so
!> an element of sector s moves as its sector-0 copy turned in time: G_e T = Rot_e G_r T,
!> with Rot_e turning harmonic h by h th_e. With equal parameters its forces and Jacobian
!> are the copy's turned alike (the contact laws do not depend on time), and since Rot_e is
!> orthogonal the selection's forces and Jacobian need only the copies:
!>   T^T G^T f = sum_r m_r (G_r T)^T f_r,   T^T G^T J G T = sum_r m_r (G_r T)^T J_r G_r T.
!> The orbits are found from G and T (nothing about sectors is given) and checked to a
!> tolerance. What they leave out, and what hbm_set_orbits cannot see, is measured at
!> every output (cond_outputs: orb_leak): the AFT samples a turned cycle at other instants
!> (a shift of a fraction of a sample), and a carried contact history need not be a
!> travelling wave (sliders frozen at different phases when a slipping flange sticks).
submodule (frirom_hbm) frirom_hbm_orbits
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_SIZE, set_status
    use frirom_aft, only: aft_eval, law_nslider
    implicit none

contains

    module procedure hbm_set_orbits
        integer(ip) :: g, e, r, q, n, nc, nrg, stat, ntot, e0
        integer(ip), allocatable :: rep(:), zc(:, :), zh(:, :), slot(:)
        logical :: known
        real(wp), allocatable :: b(:, :), br(:, :, :), sig(:, :), mult(:), gv(:), nbr(:), &
                                 sb(:)
        real(wp) :: mis, nb
        logical :: found
        type(orbit_group), allocatable :: orb(:)
        info = FRIROM_OK
        nrep = 0
        mismatch = 0.0_wp
        select type (sys => sysc)
        type is (hbm_condensed)
            ! off until orbits are found again (a failed or fruitless call leaves none)
            sys%orbits = .false.
            ntot = sum([(sys%cs%grp(g)%ne, g=1, size(sys%cs%grp))])
            nrep = ntot
            if (.not. allocated(sys%tk) .or. size(sys%cs%grp) == 0) return
            known = .false.
            if (present(map)) then
                if (size(map) /= ntot) then
                    call set_status(info, FRIROM_ERR_SIZE, errmsg, 'orbits: map must have '// &
                                    'one entry per contact element')
                    return
                end if
                known = map(1) /= 0
                if (known) known = map_valid(map, sys%cs)
                if (.not. known) map = 0
            end if
            n = sys%n
            nc = sys%nc
            call t_entries(sys, zc, zh)
            allocate (orb(size(sys%cs%grp)), gv(sys%nnl), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'orbits: work arrays')
                return
            end if
            gv = 0.0_wp
            nrep = 0
            e0 = 0
            do g = 1, size(sys%cs%grp)
                associate (gr => sys%cs%grp(g))
                    q = nc*gr%ndir
                    nrg = 0
                    allocate (b(q, n), br(q, n, 4), sig(gr%ndir*(sys%nh + 1), 4), rep(4), &
                              mult(4), nbr(4), sb(gr%ndir*(sys%nh + 1)), slot(gr%ne), &
                              stat=stat)
                    if (stat /= 0) then
                        call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'orbits: work arrays')
                        return
                    end if
                    do e = 1, gr%ne
                        if (known) then
                            ! the orbits an earlier call of this run found: the blocks of
                            ! the representatives only
                            if (map(e0 + e) /= e0 + e) then
                                r = slot(map(e0 + e) - e0)
                                mult(r) = mult(r) + 1.0_wp
                                cycle
                            end if
                        end if
                        call element_block(sys, gr, e, zc, zh, gv, b)
                        nb = norm2(b)
                        sb = block_norms(b, gr%ndir, nc, sys%nh)
                        found = .false.
                        do r = 1, merge(0_ip, nrg, known)
                            if (any(gr%params(:, e) /= gr%params(:, rep(r)))) cycle
                            call misfit(b, br(:, :, r), gr%ndir, nc, sys%nh, sb, sig(:, r), &
                                        tol*max(nb, nbr(r)), mis, found)
                            if (.not. found) cycle
                            mult(r) = mult(r) + 1.0_wp
                            if (mis > 0.0_wp) mismatch = max(mismatch, mis/max(nb, nbr(r)))
                            if (present(map)) map(e0 + e) = e0 + rep(r)
                            exit
                        end do
                        if (found) cycle
                        nrg = nrg + 1
                        if (nrg > size(rep)) then
                            call grow(br, sig, rep, mult, nbr, stat)
                            if (stat /= 0) then
                                call set_status(info, FRIROM_ERR_ALLOC, errmsg, &
                                                'orbits: representatives')
                                return
                            end if
                        end if
                        br(:, :, nrg) = b
                        sig(:, nrg) = sb
                        nbr(nrg) = nb
                        rep(nrg) = e
                        mult(nrg) = 1.0_wp
                        slot(e) = nrg
                        if (present(map)) map(e0 + e) = e0 + e
                    end do
                    call orbit_store(orb(g), gr, br(:, :, 1:nrg), rep(1:nrg), mult(1:nrg), &
                                     nc, stat)
                    deallocate (b, br, sig, rep, mult, nbr, sb, slot)
                    e0 = e0 + gr%ne
                    if (stat /= 0) then
                        call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'orbits: groups')
                        return
                    end if
                    nrep = nrep + nrg
                end associate
            end do
            if (nrep == ntot) then
                mismatch = 0.0_wp
                return
            end if
            call move_alloc(orb, sys%orb)
            if (allocated(sys%kz)) deallocate (sys%kz)
            allocate (sys%kz(n, n), stat=stat)
            if (stat /= 0) then
                deallocate (sys%orb)
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'orbits: Jacobian')
                return
            end if
            sys%orbits = .true.
            sys%orb_leak = 0.0_wp
        end select
    end procedure hbm_set_orbits

    !> T's entries by column i of z: zc(m, i) the coordinate, zh(m, i) the harmonic
    !> coefficient (1..nc) of its m-th entry (0: none); the weight is sys%tw(m, i).
    subroutine t_entries(sys, zc, zh)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), allocatable, intent(out) :: zc(:, :), zh(:, :)
        integer(ip) :: i, m, p
        allocate (zc(2, sys%n), zh(2, sys%n))
        zc = 0
        zh = 0
        do i = 1, sys%n
            do m = 1, 2
                if (sys%tk(m, i) == 0) cycle
                p = sys%sel(sys%tk(m, i))
                zc(m, i) = mod(p - 1, sys%nnl) + 1
                zh(m, i) = (p - 1)/sys%nnl + 1
            end do
        end do
    end subroutine t_entries

    !> Whether map can be an orbit map of cs: every element's representative in its own
    !> group, not after it, and a representative of itself.
    pure logical function map_valid(map, cs)
        integer(ip), intent(in) :: map(:)
        type(contact_set), intent(in) :: cs
        integer(ip) :: g, e, e0, r
        map_valid = .false.
        e0 = 0
        do g = 1, size(cs%grp)
            do e = e0 + 1, e0 + cs%grp(g)%ne
                r = map(e)
                if (r <= e0 .or. r > e) return
                if (map(r) /= r) return
            end do
            e0 = e0 + cs%grp(g)%ne
        end do
        map_valid = .true.
    end function map_valid

    !> b (nc ndir, n) = G_e T: row c + nc (d-1) is coefficient c of direction d.
    subroutine element_block(sys, gr, e, zc, zh, gv, b)
        type(hbm_condensed), intent(in) :: sys
        type(contact_group), intent(in) :: gr
        integer(ip), intent(in) :: e, zc(:, :), zh(:, :)
        real(wp), intent(inout) :: gv(:)     !! (nnl) work, zero on entry and exit
        real(wp), intent(out) :: b(:, :)
        integer(ip) :: d, row, k, i, m, nc
        nc = sys%nc
        b = 0.0_wp
        do d = 1, gr%ndir
            row = gr%row0 + (e - 1)*gr%ndir + d
            do k = sys%cs%g%p(row), sys%cs%g%p(row + 1) - 1
                gv(sys%cs%g%i(k)) = gv(sys%cs%g%i(k)) + sys%cs%g%x(k)
            end do
            do i = 1, sys%n
                do m = 1, 2
                    if (zc(m, i) == 0) cycle
                    b(zh(m, i) + nc*(d - 1), i) = b(zh(m, i) + nc*(d - 1), i) + &
                                                  sys%tw(m, i)*gv(zc(m, i))
                end do
            end do
            do k = sys%cs%g%p(row), sys%cs%g%p(row + 1) - 1
                gv(sys%cs%g%i(k)) = 0.0_wp
            end do
        end do
    end subroutine element_block

    !> The norms of b's rows by direction and harmonic (unchanged by a turn in time).
    pure function block_norms(b, ndir, nc, nh) result(s)
        real(wp), intent(in) :: b(:, :)
        integer(ip), intent(in) :: ndir, nc, nh
        real(wp) :: s(ndir*(nh + 1))
        integer(ip) :: d, h, c0
        do d = 1, ndir
            c0 = nc*(d - 1)
            s(1 + (nh + 1)*(d - 1)) = norm2(b(c0 + 1, :))
            do h = 1, nh
                s(h + 1 + (nh + 1)*(d - 1)) = norm2(b(c0 + 2*h:c0 + 2*h + 1, :))
            end do
        end do
    end function block_norms

    !> Whether b = Rot(th) br to within lim (Frobenius), th fitted on harmonic 1: a turn
    !> by t maps a cosine row a and sine row b to cos t a + sin t b, cos t b - sin t a.
    !> mis: the misfit |b - Rot(th) br|.
    subroutine misfit(b, br, ndir, nc, nh, s, sr, lim, mis, ok)
        real(wp), intent(in) :: b(:, :), br(:, :), s(:), sr(:), lim
        integer(ip), intent(in) :: ndir, nc, nh
        real(wp), intent(out) :: mis
        logical, intent(out) :: ok
        real(wp) :: m11, m12, m21, m22, th, cs, sn
        integer(ip) :: d, h, c0
        ok = .false.
        mis = huge(1.0_wp)
        if (norm2(s - sr) > lim) return
        ! harmonic 0 (not turned) first, then harmonic by harmonic; out at the first excess
        mis = 0.0_wp
        do d = 1, ndir
            mis = mis + sum((b(nc*(d - 1) + 1, :) - br(nc*(d - 1) + 1, :))**2)
        end do
        if (mis > lim**2 .or. nh == 0) then
            mis = sqrt(mis)
            ok = mis <= lim
            return
        end if
        m11 = 0.0_wp
        m12 = 0.0_wp
        m21 = 0.0_wp
        m22 = 0.0_wp
        do d = 1, ndir
            c0 = nc*(d - 1)
            m11 = m11 + dot_product(b(c0 + 2, :), br(c0 + 2, :))
            m12 = m12 + dot_product(b(c0 + 2, :), br(c0 + 3, :))
            m21 = m21 + dot_product(b(c0 + 3, :), br(c0 + 2, :))
            m22 = m22 + dot_product(b(c0 + 3, :), br(c0 + 3, :))
        end do
        th = 0.0_wp
        if (abs(m12 - m21) + abs(m11 + m22) > 0.0_wp) th = atan2(m12 - m21, m11 + m22)
        do h = 1, nh
            if (mis > lim**2) exit
            cs = cos(h*th)
            sn = sin(h*th)
            do d = 1, ndir
                c0 = nc*(d - 1)
                mis = mis + sum((b(c0 + 2*h, :) - cs*br(c0 + 2*h, :) - &
                                 sn*br(c0 + 2*h + 1, :))**2) + &
                      sum((b(c0 + 2*h + 1, :) - cs*br(c0 + 2*h + 1, :) + &
                           sn*br(c0 + 2*h, :))**2)
            end do
        end do
        mis = sqrt(mis)
        ok = mis <= lim
    end subroutine misfit

    !> Twice the room for representatives.
    subroutine grow(br, sig, rep, mult, nbr, stat)
        real(wp), allocatable, intent(inout) :: br(:, :, :), sig(:, :), mult(:), nbr(:)
        integer(ip), allocatable, intent(inout) :: rep(:)
        integer(ip), intent(out) :: stat
        real(wp), allocatable :: br2(:, :, :), sig2(:, :), mult2(:), nbr2(:)
        integer(ip), allocatable :: rep2(:)
        integer(ip) :: k
        k = size(rep)
        allocate (br2(size(br, 1), size(br, 2), 2*k), sig2(size(sig, 1), 2*k), rep2(2*k), &
                  mult2(2*k), nbr2(2*k), stat=stat)
        if (stat /= 0) return
        br2(:, :, 1:k) = br
        sig2(:, 1:k) = sig
        rep2(1:k) = rep
        mult2(1:k) = mult
        nbr2(1:k) = nbr
        call move_alloc(br2, br)
        call move_alloc(sig2, sig)
        call move_alloc(rep2, rep)
        call move_alloc(mult2, mult)
        call move_alloc(nbr2, nbr)
    end subroutine grow

    !> An orbit group from its representatives' blocks br (q, n, nrep).
    subroutine orbit_store(og, gr, br, rep, mult, nc, stat)
        type(orbit_group), intent(out) :: og
        type(contact_group), intent(in) :: gr
        real(wp), intent(in) :: br(:, :, :), mult(:)
        integer(ip), intent(in) :: rep(:), nc
        integer(ip), intent(out) :: stat
        integer(ip) :: q, n, nr, r
        q = size(br, 1)
        n = size(br, 2)
        nr = size(rep)
        og%nrep = nr
        allocate (og%gz(q*nr, n), og%x(nc, gr%ndir, nr), og%f(nc, gr%ndir, nr), &
                  og%jac(q, q, nr), og%params(size(gr%params, 1), nr), &
                  og%w0(size(gr%w0, 1), nr), og%states(3, nr), og%y(q*nr, n), stat=stat)
        if (stat /= 0) return
        do r = 1, nr
            og%gz(q*(r - 1) + 1:q*r, :) = br(:, :, r)
        end do
        og%rep = rep
        og%mult = mult
        og%params = gr%params(:, rep)
    end subroutine orbit_store

    module procedure orbit_forces
        integer(ip) :: g, r, q, m, n, nr
        info = FRIROM_OK
        n = sys%n
        fz = 0.0_wp
        if (jac) sys%kz = 0.0_wp
        do g = 1, size(sys%orb)
            associate (og => sys%orb(g), gr => sys%cs%grp(g))
                nr = og%nrep
                if (nr == 0) cycle
                q = sys%nc*gr%ndir
                m = q*nr
                call dgemv('N', m, n, 1.0_wp, og%gz, m, z, 1, 0.0_wp, og%x, 1)
                if (law_nslider(gr%law) > 0) og%w0 = gr%w0(:, og%rep)
                if (jac) then
                    call aft_eval(sys%plan, gr%law, og%x, og%params, og%w0, og%f, info, &
                                  errmsg, jac=og%jac, states=og%states, relative=.true.)
                else
                    call aft_eval(sys%plan, gr%law, og%x, og%params, og%w0, og%f, info, &
                                  errmsg, states=og%states, relative=.true.)
                end if
                if (info /= 0) return
                if (allocated(gr%ks)) then
                    if (jac) then
                        call free_subtract(gr%ks(:, og%rep), gr%kp(:, og%rep), og%x, og%f, og%jac)
                    else
                        call free_subtract(gr%ks(:, og%rep), gr%kp(:, og%rep), og%x, og%f)
                    end if
                end if
                do r = 1, nr
                    og%f(:, :, r) = og%mult(r)*og%f(:, :, r)
                end do
                ! fz += sum_r m_r (G_r T)^T f_r
                call dgemv('T', m, n, 1.0_wp, og%gz, m, og%f, 1, 1.0_wp, fz, 1)
                if (.not. jac) cycle
                ! kz += sum_r (G_r T)^T (m_r J_r G_r T)
                do r = 1, nr
                    call dgemm('N', 'N', q, n, q, og%mult(r), og%jac(:, :, r), q, &
                               og%gz(q*(r - 1) + 1, 1), m, 0.0_wp, og%y(q*(r - 1) + 1, 1), m)
                end do
                call dgemm('T', 'N', n, n, m, 1.0_wp, og%gz, m, og%y, m, 1.0_wp, sys%kz, n)
            end associate
        end do
    end procedure orbit_forces

end submodule frirom_hbm_orbits
