!> frirom_hbm contact_assemble into a dense matrix: the matrix products it takes for a
!> group whose rows are dense over its columns (an interface reduced to GSI modes) against
!> the element loops (loops = .true., the path every earlier release took), on random G
!> and random local Jacobians: dense columns (all of them, or a scattered subset with a
!> column map and a wider harmonic stride), and sparse rows (where the loops are kept).
!> Tolerance 1e-12 relative: the same sums in another order, ~50 terms of size ~1.
!> The same for contact_eval's G x and G^T f (matrix products over a dense group's columns
!> against the sparse rows, gx_mode = 1), through a cubic spring's AFT; and for a group
!> whose rows are dense only over the columns their direction reads (MS coordinates: the
!> products per direction, gx_mode 3), through normal1d's AFT, with and without a
!> selection (keep: G x over the kept columns only, xd zero elsewhere; two masks, so the
!> kept plan is rebuilt). Same tolerance: the same sums in another order.
program test_assemble
    use frirom_kinds, only: wp, ip
    use frirom_check, only: check, check_done
    use frirom_hbm, only: contact_set, contact_assemble, contact_eval
    use frirom_aft, only: aft_plan, aft_plan_create, LAW_CUBIC, LAW_NORMAL1D
    implicit none
    call compare('dense, 40 columns, normal1d, H = 1', ne=30, nd=2, nh=1, ncol=40, &
                 per_row=40, stride=0)
    call compare('dense, 12 of 30 columns, normal2d, H = 3, column map', ne=9, nd=3, nh=3, &
                 ncol=30, per_row=12, stride=5)
    call compare('sparse rows (element loops kept), 60 columns, H = 2', ne=20, nd=2, nh=2, &
                 ncol=60, per_row=3, stride=0)
    call compare_dir()
    call check_done('test_assemble')

contains

    !> Random contact set: ne elements of nd directions, each row reading per_row of the
    !> ncol columns (the same per_row for the whole group when per_row > 3: dense GSI-like
    !> rows; else 3 random ones); stride > 0 maps column j to j + stride (a colmap) and
    !> uses ldc = ncol + 2 stride.
    subroutine compare(name, ne, nd, nh, ncol, per_row, stride)
        character(len=*), intent(in) :: name
        integer(ip), intent(in) :: ne, nd, nh, ncol, per_row, stride
        type(contact_set) :: cs
        real(wp), allocatable :: k1(:, :), k2(:, :)
        integer(ip), allocatable :: sub(:), colmap(:)
        real(wp) :: u(ncol)
        integer(ip) :: nc, nr, r, k, info, ldc, j
        character(len=200) :: msg
        nc = 2*nh + 1
        nr = ne*nd
        cs%nc = nc
        cs%g%nrow = nr
        cs%g%ncol = ncol
        allocate (cs%g%p(nr + 1), cs%g%i(nr*per_row), cs%g%x(nr*per_row))
        ! the group's columns: a random subset of per_row (dense) or 3 per row
        call random_number(u)
        sub = sort_idx(u, per_row)
        do r = 1, nr
            cs%g%p(r) = (r - 1)*per_row + 1
            if (per_row <= 3) then
                call random_number(u)
                sub = sort_idx(u, per_row)
            end if
            cs%g%i(cs%g%p(r):cs%g%p(r) + per_row - 1) = sub
        end do
        cs%g%p(nr + 1) = nr*per_row + 1
        call random_number(cs%g%x)
        cs%g%x = cs%g%x - 0.5_wp
        allocate (cs%grp(1))
        cs%grp(1)%ne = ne
        cs%grp(1)%ndir = nd
        cs%grp(1)%row0 = 0
        allocate (cs%grp(1)%jac(nc*nd, nc*nd, ne))
        call random_number(cs%grp(1)%jac)
        cs%grp(1)%jac = cs%grp(1)%jac - 0.5_wp
        cs%grp(1)%jac(1, 2, 1) = 0.0_wp         ! an exact zero (skipped) among the entries
        ldc = ncol + 2*stride
        allocate (k1(ldc*nc, ldc*nc), k2(ldc*nc, ldc*nc), colmap(ncol))
        colmap = [(j + stride, j=1, ncol)]
        call random_number(k1)
        k2 = k1                                 ! both add to the same existing entries
        if (stride > 0) then
            call contact_assemble(cs, kd=k1, info=info, errmsg=msg, colmap=colmap, ldc=ldc)
            call check(info == 0, name//': '//trim(msg))
            call contact_assemble(cs, kd=k2, info=info, errmsg=msg, colmap=colmap, ldc=ldc, &
                                  loops=.true.)
        else
            call contact_assemble(cs, kd=k1, info=info, errmsg=msg)
            call check(info == 0, name//': '//trim(msg))
            call contact_assemble(cs, kd=k2, info=info, errmsg=msg, loops=.true.)
        end if
        call check(info == 0, name//' (loops): '//trim(msg))
        k = 0
        print '(a,a,es10.2)', name, ': max |products - loops| / max |loops| =', &
            maxval(abs(k1 - k2))/maxval(abs(k2))
        call check(maxval(abs(k1 - k2)) <= 1.0e-12_wp*maxval(abs(k2)), name)
        call compare_eval(cs, name, per_row > 3)
    end subroutine compare

    !> contact_eval of the set as chosen (products when expect_dense) against the sparse
    !> rows: the local displacements and the forces on the columns, 1e-12 relative.
    subroutine compare_eval(cs, name, expect_dense)
        type(contact_set), intent(inout) :: cs
        character(len=*), intent(in) :: name
        logical, intent(in) :: expect_dense
        type(contact_set) :: loops
        type(aft_plan) :: plan
        real(wp), allocatable :: xd(:, :), f1(:, :), f2(:, :)
        integer(ip) :: nc, ne, nd, info
        character(len=200) :: msg
        nc = cs%nc
        ne = cs%grp(1)%ne
        nd = cs%grp(1)%ndir
        cs%grp(1)%law = LAW_CUBIC
        allocate (cs%grp(1)%params(2, nd*ne))
        cs%grp(1)%params(1, :) = 1.0e3_wp   ! k1, N/m
        cs%grp(1)%params(2, :) = 5.0e2_wp   ! k3, N/m^3
        allocate (cs%grp(1)%w0(0, nd*ne), cs%grp(1)%x(nc, 1, nd*ne), &
                  cs%grp(1)%f(nc, 1, nd*ne), cs%grp(1)%states(3, nd*ne))
        cs%grp(1)%ne = nd*ne   ! one cubic spring per row of G
        cs%grp(1)%ndir = 1
        loops = cs
        loops%grp(1)%gx_mode = 1
        allocate (xd(cs%g%ncol, nc), f1(cs%g%ncol, nc), f2(cs%g%ncol, nc))
        call random_number(xd)
        xd = 1.0e-2_wp*(xd - 0.5_wp)
        call aft_plan_create(plan, (nc - 1)/2, 4*nc, info, msg)
        call check(info == 0, name//': plan: '//trim(msg))
        call contact_eval(cs, plan, xd, f1, .false., info, msg)
        call check(info == 0, name//': contact_eval: '//trim(msg))
        call check((cs%grp(1)%gx_mode == 2) .eqv. expect_dense, name//': G x by products')
        call contact_eval(loops, plan, xd, f2, .false., info, msg)
        call check(info == 0, name//': contact_eval (rows): '//trim(msg))
        print '(a,a,es10.2)', name, ': contact_eval max |products - rows| / max |rows| =', &
            maxval(abs(f1 - f2))/maxval(abs(f2))
        call check(maxval(abs(cs%grp(1)%x - loops%grp(1)%x)) <= &
                   1.0e-12_wp*maxval(abs(loops%grp(1)%x)), name//': G x')
        call check(maxval(abs(f1 - f2)) <= 1.0e-12_wp*maxval(abs(f2)), name//': G^T f')
    end subroutine compare_eval

    !> normal1d elements whose tangential rows read 20 of columns 1..24 and normal rows 20
    !> of 21..44 (dense per direction, not over the group: gx_mode 3), H = 2:
    !> contact_eval against the sparse rows, without and with two selections.
    subroutine compare_dir()
        integer(ip), parameter :: ne = 25, nd = 2, nh = 2, ncol = 44, per_row = 20
        character(len=*), parameter :: name = 'dense per direction, normal1d, H = 2'
        type(contact_set) :: cs, loops
        type(aft_plan) :: plan
        real(wp), allocatable :: xd(:, :), f1(:, :), f2(:, :)
        real(wp) :: u(ncol, 0:nh), pool(24)
        logical :: keep(ncol, 0:nh)
        integer(ip) :: nc, nr, r, d, j, info, pass
        character(len=200) :: msg
        nc = 2*nh + 1
        nr = ne*nd
        cs%nc = nc
        cs%g%nrow = nr
        cs%g%ncol = ncol
        allocate (cs%g%p(nr + 1), cs%g%i(nr*per_row), cs%g%x(nr*per_row))
        do r = 1, nr
            d = mod(r - 1, nd) + 1
            cs%g%p(r) = (r - 1)*per_row + 1
            call random_number(pool)
            cs%g%i(cs%g%p(r):cs%g%p(r) + per_row - 1) = sort_idx(pool, per_row) + 20*(d - 1)
        end do
        cs%g%p(nr + 1) = nr*per_row + 1
        call random_number(cs%g%x)
        cs%g%x = cs%g%x - 0.5_wp
        allocate (cs%grp(1))
        cs%grp(1)%law = LAW_NORMAL1D
        cs%grp(1)%ne = ne
        cs%grp(1)%ndir = nd
        cs%grp(1)%row0 = 0
        allocate (cs%grp(1)%params(4, ne), cs%grp(1)%w0(1, ne), cs%grp(1)%x(nc, nd, ne), &
                  cs%grp(1)%f(nc, nd, ne), cs%grp(1)%states(3, ne))
        cs%grp(1)%params(1, :) = 1.0e3_wp   ! kt, N/m
        cs%grp(1)%params(2, :) = 2.0e3_wp   ! kn, N/m
        cs%grp(1)%params(3, :) = 0.3_wp     ! mu
        cs%grp(1)%params(4, :) = 2.0_wp     ! n0, N: slip and lift-off at |x| ~ 1e-3
        cs%grp(1)%w0 = 0.0_wp
        loops = cs
        loops%grp(1)%gx_mode = 1
        allocate (xd(ncol, nc), f1(ncol, nc), f2(ncol, nc))
        call aft_plan_create(plan, nh, 4*nc, info, msg)
        call check(info == 0, name//': plan: '//trim(msg))
        do pass = 0, 2
            call random_number(xd)
            xd = 2.0e-3_wp*(xd - 0.5_wp)
            if (pass == 0) then
                call contact_eval(cs, plan, xd, f1, .false., info, msg)
            else
                call random_number(u)
                keep = u < 0.5_wp
                do j = 1, nc
                    where (.not. keep(:, j/2)) xd(:, j) = 0.0_wp
                end do
                call contact_eval(cs, plan, xd, f1, .false., info, msg, keep=keep)
            end if
            call check(info == 0, name//': contact_eval: '//trim(msg))
            call check(cs%grp(1)%gx_mode == 3, name//': G x by products per direction')
            call contact_eval(loops, plan, xd, f2, .false., info, msg)
            call check(info == 0, name//': contact_eval (rows): '//trim(msg))
            print '(a,a,i2,a,es10.2)', name, ', selection', pass, &
                ': contact_eval max |products - rows| / max |rows| =', &
                maxval(abs(f1 - f2))/maxval(abs(f2))
            call check(maxval(abs(cs%grp(1)%x - loops%grp(1)%x)) <= &
                       1.0e-12_wp*maxval(abs(loops%grp(1)%x)), name//': G x')
            call check(maxval(abs(f1 - f2)) <= 1.0e-12_wp*maxval(abs(f2)), name//': G^T f')
        end do
    end subroutine compare_dir

    !> Indices of the m smallest entries of u, ascending by index (a random m-subset).
    function sort_idx(u, m) result(idx)
        real(wp), intent(in) :: u(:)
        integer(ip), intent(in) :: m
        integer(ip), allocatable :: idx(:)
        logical :: take(size(u))
        integer(ip) :: j
        take = .false.
        do j = 1, m
            take(minloc(u, 1, mask=.not. take)) = .true.
        end do
        idx = pack([(j, j=1, size(u))], take)
    end function sort_idx
end program test_assemble
