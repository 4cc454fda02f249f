!> The travelling-wave selection of a condensed system (hbm_set_selection: the kept
!> (coordinate, harmonic) pairs, and the pairs of coordinates that fix the wave's
!> direction), the maps between its unknowns and the full layout, and its leaks: what the
!> contact forces, the loads' response and the orbits put off the selection.
submodule (frirom_hbm:frirom_hbm_condensed) frirom_hbm_select
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_ALLOC, FRIROM_ERR_PARAM, FRIROM_ERR_SIZE, &
                             set_status, failed
    implicit none

contains

    module procedure hbm_set_selection
        integer(ip) :: nu, nc, h, j, c, k, n, m, i, q, stat
        integer(ip), allocatable :: ksel(:), kpt(:), kptr(:), at(:, :), tk(:, :), ptn(:, :)
        real(wp), allocatable :: tw(:, :), jm(:, :), jk(:, :), twm(:, :)
        integer(ip), allocatable :: ipiv(:), tkm(:, :), kpr(:, :)
        logical, allocatable :: kmask(:, :)
        real(wp) :: on, off
        info = FRIROM_OK
        select type (sys => sysc)
        type is (hbm_condensed)
            nu = sys%nnl
            nc = sys%nc
            if (size(keep, 1) /= nu .or. size(keep, 2) /= sys%nh + 1) then
                call set_status(info, FRIROM_ERR_SIZE, errmsg, 'selection: keep must be '// &
                                '(nonlinear DoFs, H+1)')
            else if (sys%tcontact) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs the '// &
                                'unknowns in the nonlinear DoFs, not in contact coordinates')
            else if (use_krylov(sys)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs direct '// &
                                'solves (krylov off)')
            else if (all(keep == 0)) then
                call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: keeps no unknown')
            end if
            if (info /= 0) return
            if (present(pair)) then
                call check_pairs(keep, pair, ptn, info, errmsg)
                if (info /= 0) return
            end if
            ! everything is built in locals first: a failed call leaves sys as it was
            n = 0
            do c = 1, nc
                n = n + count(keep(:, c/2) /= 0)
            end do
            allocate (kptr(sys%nh + 2), kpt(count(keep /= 0)), ksel(n), at(nu, nc), &
                      tk(2, n), tw(2, n), kmask(nu, 0:sys%nh), stat=stat)
            if (stat /= 0) then
                call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'selection: index arrays')
                return
            end if
            kptr(1) = 1
            k = 0
            do h = 0, sys%nh
                do j = 1, nu
                    if (keep(j, h) == 0) cycle
                    k = k + 1
                    kpt(k) = j
                end do
                kptr(h + 2) = k + 1
            end do
            ! y: coefficient by coefficient (harmonic c/2), the kept coordinates ascending;
            ! at(j, c) its position (0: left out)
            k = 0
            at = 0
            do c = 1, nc
                h = c/2
                do i = kptr(h + 1), kptr(h + 2) - 1
                    k = k + 1
                    ksel(k) = kpt(i) + nu*(c - 1)
                    at(kpt(i), c) = k
                end do
            end do
            ! T: in the kept order, a pair's column where its first member (j, the cosine
            ! or sine of a coordinate with pair(j, h) /= 0) is, none for its second (k)
            m = 0
            do i = 1, n
                j = mod(ksel(i) - 1, nu) + 1
                c = (ksel(i) - 1)/nu + 1
                h = c/2
                m = m + 1
                tk(:, m) = [i, 0_ip]
                tw(:, m) = [1.0_wp, 0.0_wp]
                if (.not. present(pair) .or. h == 0) cycle
                if (ptn(j, h) /= 0) then
                    m = m - 1                         ! a second member: in its pair's column
                else if (pair(j, h) /= 0) then
                    q = abs(pair(j, h))
                    if (c == 2*h) then                ! (y(j, cos) + s y(q, sin)) / sqrt 2
                        tk(2, m) = at(q, c + 1)
                        tw(:, m) = [1.0_wp, real(sign(1_ip, pair(j, h)), wp)]/sqrt(2.0_wp)
                    else                              ! (y(j, sin) - s y(q, cos)) / sqrt 2
                        tk(2, m) = at(q, c - 1)
                        tw(:, m) = [1.0_wp, -real(sign(1_ip, pair(j, h)), wp)]/sqrt(2.0_wp)
                    end if
                end if
            end do
            if (m < n) then
                allocate (jk(n, m), stat=stat)
            else
                allocate (jk(0, 0), stat=stat)
            end if
            if (stat == 0) allocate (jm(m, m), ipiv(m), stat=stat)
            if (stat == 0 .and. m < n) then
                allocate (tkm(2, m), twm(2, m), kpr(nu, 0:sys%nh), stat=stat)
                if (stat == 0) then
                    tkm = tk(:, 1:m)
                    twm = tw(:, 1:m)
                    kpr = pair
                end if
            end if
            if (failed(stat /= 0, info, FRIROM_ERR_ALLOC, errmsg, 'selection: Jacobian')) return
            call move_alloc(kptr, sys%kptr)
            call move_alloc(kpt, sys%kpt)
            call move_alloc(ksel, sys%sel)
            call move_alloc(jm, sys%jm)
            call move_alloc(ipiv, sys%held%ipiv)
            if (allocated(sys%tk)) deallocate (sys%tk, sys%tw, sys%jk, sys%kpair)
            if (m < n) then
                call move_alloc(tkm, sys%tk)
                call move_alloc(twm, sys%tw)
                call move_alloc(kpr, sys%kpair)
                call move_alloc(jk, sys%jk)
            end if
            ! the residual's mode rows (sel_rows) were cut for the selection before
            if (allocated(sys%prow)) deallocate (sys%prow)
            ! orbits hold blocks of the old T (hbm_set_orbits again)
            sys%orbits = .false.
            sys%orb_leak = 0.0_wp
            if (allocated(sys%orb)) deallocate (sys%orb)
            if (allocated(sys%kz)) deallocate (sys%kz)
            kmask = keep /= 0
            call move_alloc(kmask, sys%kmask)
            sys%n = m
            if (allocated(sys%jcur)) deallocate (sys%jcur)
            if (allocated(sys%held%lus)) deallocate (sys%held%lus)
            if (allocated(sys%kcw)) deallocate (sys%kcw)
            sys%lu_any = .false.
            sys%lu_fresh = .false.
            sys%held%single = .false.
            sys%gm_worth = 0.0_wp
            sys%c0_leak = 0.0_wp
            sys%xe_leak = 0.0_wp
            if (allocated(sys%cs%c0)) then
                on = sum(sys%cs%c0**2, mask=keep(:, 0) /= 0)
                off = sum(sys%cs%c0**2, mask=keep(:, 0) == 0)
                sys%c0_leak = ratio(off, on)
            end if
            if (present(sel)) sel = sys%sel
        class default
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: needs the '// &
                            'condensed formulation')
        end select
    end procedure hbm_set_selection

    !> Check hbm_set_selection's pair against keep: pairs at harmonics >= 1 only, between
    !> two different coordinates both kept there, each coordinate in one pair at most;
    !> ptn(k, h) = j for the second member k of j's pair, else 0.
    subroutine check_pairs(keep, pair, ptn, info, errmsg)
        integer(ip), intent(in) :: keep(:, 0:), pair(:, 0:)
        integer(ip), allocatable, intent(out) :: ptn(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nu, nh, h, j, q, stat
        info = FRIROM_OK
        nu = size(keep, 1)
        nh = size(keep, 2) - 1
        if (size(pair, 1) /= nu .or. size(pair, 2) /= nh + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'selection: pair must be '// &
                            '(nonlinear DoFs, H+1)')
            return
        end if
        allocate (ptn(nu, 0:nh), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'selection: pairs')
            return
        end if
        ptn = 0
        if (any(pair(:, 0) /= 0)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair at harmonic 0 '// &
                            '(it has no sine)')
            return
        end if
        do h = 1, nh
            do j = 1, nu
                q = abs(pair(j, h))
                if (q == 0) cycle
                if (q > nu .or. q == j) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair names '// &
                                    'no other coordinate')
                else if (keep(j, h) == 0 .or. keep(q, h) == 0) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: pair of a '// &
                                    'coordinate and harmonic left out')
                else if (pair(q, h) /= 0 .or. ptn(q, h) /= 0 .or. ptn(j, h) /= 0) then
                    call set_status(info, FRIROM_ERR_PARAM, errmsg, 'selection: a '// &
                                    'coordinate in two pairs')
                end if
                if (info /= 0) return
                ptn(q, h) = j
            end do
        end do
    end subroutine check_pairs

    module procedure hbm_sel_expand
        integer(ip) :: i
        real(wp), allocatable :: yk(:)
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. allocated(sys%sel)) then
                yf = y
                return
            end if
            yf = 0.0_wp
            if (allocated(sys%tk)) then
                allocate (yk(size(sys%sel)))
                call pair_expand(sys, y, yk)
                yf(sys%sel) = yk
            else
                do i = 1, size(sys%sel)
                    yf(sys%sel(i)) = y(i)
                end do
            end if
        class default
            yf = y
        end select
    end procedure hbm_sel_expand

    module procedure hbm_sel_reduce
        select type (sys => sysc)
        type is (hbm_condensed)
            if (.not. allocated(sys%sel)) then
                y = yf
            else if (allocated(sys%tk)) then
                call pair_reduce(sys, yf(sys%sel), y)
            else
                y = yf(sys%sel)
            end if
        class default
            y = yf
        end select
    end procedure hbm_sel_reduce

    !> yk = T z (kept layout; hbm_condensed%tk).
    pure subroutine pair_expand(sys, z, yk)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: z(:)
        real(wp), intent(out) :: yk(:)
        integer(ip) :: i
        yk = 0.0_wp
        do i = 1, size(sys%tk, 2)
            yk(sys%tk(1, i)) = sys%tw(1, i)*z(i)
            if (sys%tk(2, i) > 0) yk(sys%tk(2, i)) = sys%tw(2, i)*z(i)
        end do
    end subroutine pair_expand

    !> z = T^T yk (kept layout; hbm_condensed%tk).
    pure subroutine pair_reduce(sys, yk, z)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(in) :: yk(:)
        real(wp), intent(out) :: z(:)
        integer(ip) :: i
        do i = 1, size(sys%tk, 2)
            z(i) = sys%tw(1, i)*yk(sys%tk(1, i))
            if (sys%tk(2, i) > 0) z(i) = z(i) + sys%tw(2, i)*yk(sys%tk(2, i))
        end do
    end subroutine pair_reduce

    module procedure cond_leak
        integer(ip) :: c
        real(wp) :: on, off
        leak = 0.0_wp
        if (.not. allocated(sys%sel) .or. .not. allocated(sys%fd)) return
        ! each part summed on its own: a leak at round-off is not lost to cancellation
        call fd_split(sys, on, off)
        ! the pairs: the other travelling direction counts as off the selection too
        if (allocated(sys%tk)) then
            do c = 1, sys%nh
                off = off + pair_off(sys, c, sys%fd(:, 2*c), sys%fd(:, 2*c + 1))
            end do
        end if
        leak = max(ratio(off, on), sys%c0_leak, sys%xe_leak, sys%orb_leak)
    end procedure cond_leak

    !> The squares of the contact forces sys%fd summed on the kept rows (on) and off them
    !> (off), harmonic by harmonic (a selected system).
    pure subroutine fd_split(sys, on, off)
        type(hbm_condensed), intent(in) :: sys
        real(wp), intent(out) :: on, off
        integer(ip) :: c
        on = 0.0_wp
        off = 0.0_wp
        do c = 1, sys%nc
            on = on + sum(sys%fd(:, c)**2, mask=sys%kmask(:, c/2))
            off = off + sum(sys%fd(:, c)**2, mask=.not. sys%kmask(:, c/2))
        end do
    end subroutine fd_split

    !> The part of harmonic h (cosines a, sines b by coordinate) against its pairs
    !> (hbm_condensed%kpair), squared: sum over the pairs (j, k, s) of
    !> ((a_j - s b_k)^2 + (b_j + s a_k)^2) / 2, the wave in the other direction.
    pure real(wp) function pair_off(sys, h, a, b) result(off)
        type(hbm_condensed), intent(in) :: sys
        integer(ip), intent(in) :: h
        real(wp), intent(in) :: a(:), b(:)
        integer(ip) :: j, k
        real(wp) :: s
        off = 0.0_wp
        do j = 1, sys%nnl
            k = abs(sys%kpair(j, h))
            if (k == 0) cycle
            s = real(sign(1_ip, sys%kpair(j, h)), wp)
            off = off + 0.5_wp*((a(j) - s*b(k))**2 + (b(j) + s*a(k))**2)
        end do
    end function pair_off

    module procedure load_leak
        complex(wp), allocatable :: x1(:, :), b1(:, :), xe(:)
        real(wp), allocatable :: xr(:, :), br(:, :)
        real(wp) :: on, off
        integer(ip) :: h, nm, nu
        on = 0.0_wp
        off = 0.0_wp
        nu = sys%nnl
        allocate (xe(nu))
        if (allocated(sys%phr)) then
            ! every harmonic in one product (phr is the same for all)
            nm = size(sys%phr, 2)
            allocate (xr(nm, 2*(sys%nh + 1)), br(nu, 2*(sys%nh + 1)))
            do h = 0, sys%nh
                xr(:, 2*h + 1) = real(sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h)), wp)
                xr(:, 2*h + 2) = aimag(sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h)))
            end do
            call dgemm('N', 'N', nu, 2*(sys%nh + 1), nm, 1.0_wp, sys%phr, size(sys%phr, 1), &
                       xr, nm, 0.0_wp, br, nu)
        else if (sys%modal) then
            allocate (x1(size(sys%g, 1), 1), b1(nu, 1))
        end if
        do h = 0, sys%nh
            if (allocated(sys%phr)) then
                xe = cmplx(br(:, 2*h + 1), br(:, 2*h + 2), wp)
            else if (sys%modal) then
                x1(:, 1) = sys%g(:, h)*(sys%qf(:, h) + s*sys%qf1(:, h))
                call modal_apply(sys, h, 1, nu, x1, b1)
                xe = b1(:, 1)
            else
                xe = sys%tye0(:, h) + s*sys%tye1(:, h)
            end if
            on = on + sum(abs(xe)**2, mask=sys%kmask(:, h))
            off = off + sum(abs(xe)**2, mask=.not. sys%kmask(:, h))
            ! harm_col: cosine real(xe), sine -aimag(xe)
            if (allocated(sys%tk) .and. h > 0) off = off + pair_off(sys, h, real(xe, wp), &
                                                                     -aimag(xe))
        end do
        sys%xe_leak = ratio(off, on)
    end procedure load_leak

    module procedure orbit_leak
        real(wp), allocatable :: fz(:), fa(:)
        allocate (fz(sys%n), fa(sys%n))
        call orbit_forces(sys, y, .false., fz, info, errmsg)
        if (info /= 0) return
        call hbm_sel_reduce(sys, reshape(sys%fd, [size(sys%fd)]), fa)
        sys%orb_leak = ratio(sum((fa - fz)**2), sum(fz**2))
    end procedure orbit_leak

    module procedure sel_only
        real(wp), parameter :: OUT_SKIP = 1.0e-12_wp
        real(wp) :: on, off
        sel_only = .false.
        if (.not. allocated(sys%sel)) return
        call fd_split(sys, on, off)
        sel_only = off <= OUT_SKIP**2*on
        if (sel_only) call sel_rows(sys)
    end procedure sel_only
end submodule frirom_hbm_select
