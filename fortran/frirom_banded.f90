!> Banded matrices in LAPACK's factorisation layout, their LU factorisation and solves
!> (dgbtrf/dgbtrs, zgbtrf/zgbtrs with `info` translated into frirom codes), and the reverse
!> Cuthill-McKee ordering that makes a sparse symmetric pattern banded.
module frirom_banded
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_ALLOC, FRIROM_ERR_LAPACK, FRIROM_ERR_SINGULAR, &
                             set_status
    implicit none
    private
    public :: band_matrix, zband_matrix, band_init, band_zero, band_add, band_factor, &
              band_solve, zband_init, zband_zero, zband_add, zband_factor, zband_solve, &
              rcm_order, band_width

    !> Real banded matrix, n x n, kl sub- and ku super-diagonals, stored for dgbtrf:
    !> A(i, j) lives in ab(kl + ku + 1 + i - j, j); the first kl rows are LU fill space.
    type :: band_matrix
        integer(ip) :: n = 0, kl = 0, ku = 0
        real(wp), allocatable :: ab(:, :)   !! (2 kl + ku + 1, n)
        integer(ip), allocatable :: ipiv(:) !! (n) pivots of the factorisation
        logical :: factored = .false.
    end type band_matrix

    !> Complex banded matrix, same layout as band_matrix (zgbtrf).
    type :: zband_matrix
        integer(ip) :: n = 0, kl = 0, ku = 0
        complex(wp), allocatable :: ab(:, :)
        integer(ip), allocatable :: ipiv(:)
        logical :: factored = .false.
    end type zband_matrix

    interface
        subroutine dgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, kl, ku, ldab
            real(wp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine dgbtrf
        subroutine dgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb, ipiv(*)
            real(wp), intent(in) :: ab(ldab, *)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgbtrs
        subroutine zgbtrf(m, n, kl, ku, ab, ldab, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, kl, ku, ldab
            complex(wp), intent(inout) :: ab(ldab, *)
            integer, intent(out) :: ipiv(*), info
        end subroutine zgbtrf
        subroutine zgbtrs(trans, n, kl, ku, nrhs, ab, ldab, ipiv, b, ldb, info)
            import :: wp
            character, intent(in) :: trans
            integer, intent(in) :: n, kl, ku, nrhs, ldab, ldb, ipiv(*)
            complex(wp), intent(in) :: ab(ldab, *)
            complex(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine zgbtrs
    end interface

contains

    !> Allocate an n x n real banded matrix with kl sub- and ku super-diagonals, zeroed.
    subroutine band_init(a, n, kl, ku, info, errmsg)
        type(band_matrix), intent(inout) :: a
        integer(ip), intent(in) :: n, kl, ku        !! order and bandwidths
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: stat
        info = FRIROM_OK
        if (n < 1 .or. kl < 0 .or. ku < 0 .or. kl > n - 1 .or. ku > n - 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'band_init: need n >= 1 and '// &
                            '0 <= kl, ku <= n-1')
            return
        end if
        if (allocated(a%ab)) deallocate (a%ab)
        if (allocated(a%ipiv)) deallocate (a%ipiv)
        allocate (a%ab(2*kl + ku + 1, n), a%ipiv(n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'band_init: banded matrix')
            return
        end if
        a%n = n
        a%kl = kl
        a%ku = ku
        call band_zero(a)
    end subroutine band_init

    !> Set every entry to zero (keeps the allocation) and mark the matrix unfactored.
    subroutine band_zero(a)
        type(band_matrix), intent(inout) :: a
        a%ab = 0.0_wp
        a%factored = .false.
    end subroutine band_zero

    !> A(i, j) += v. Entries outside the band are a caller error: `ok` comes back false.
    pure subroutine band_add(a, i, j, v, ok)
        type(band_matrix), intent(inout) :: a
        integer(ip), intent(in) :: i, j   !! row and column, 1-based
        real(wp), intent(in) :: v
        logical, intent(inout) :: ok      !! set to false when (i, j) lies outside the band
        if (i - j > a%kl .or. j - i > a%ku) then
            ok = .false.
            return
        end if
        a%ab(a%kl + a%ku + 1 + i - j, j) = a%ab(a%kl + a%ku + 1 + i - j, j) + v
    end subroutine band_add

    !> LU factorisation in place (dgbtrf).
    subroutine band_factor(a, info, errmsg)
        type(band_matrix), intent(inout) :: a
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: linfo
        character(len=24) :: buf
        info = FRIROM_OK
        call dgbtrf(a%n, a%n, a%kl, a%ku, a%ab, size(a%ab, 1), a%ipiv, linfo)
        if (linfo > 0) then
            write (buf, '(i0)') linfo
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'dgbtrf: zero pivot in row '// &
                            trim(buf))
        else if (linfo < 0) then
            write (buf, '(i0)') -linfo
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'dgbtrf: illegal argument '// &
                            trim(buf))
        else
            a%factored = .true.
        end if
    end subroutine band_factor

    !> Solve A x = b for the columns of b (overwritten by x) with the factorisation of A.
    subroutine band_solve(a, b, info, errmsg)
        type(band_matrix), intent(in) :: a
        real(wp), intent(inout) :: b(:, :)   !! (n, nrhs) right-hand sides in, solutions out
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: linfo
        info = FRIROM_OK
        if (.not. a%factored) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'band_solve: matrix not factored')
            return
        end if
        if (size(b, 1) /= a%n) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'band_solve: b has wrong row count')
            return
        end if
        call dgbtrs('N', a%n, a%kl, a%ku, size(b, 2), a%ab, size(a%ab, 1), a%ipiv, b, &
                    size(b, 1), linfo)
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, &
                                        'dgbtrs: illegal argument')
    end subroutine band_solve

    !> Allocate an n x n complex banded matrix, zeroed.
    subroutine zband_init(a, n, kl, ku, info, errmsg)
        type(zband_matrix), intent(inout) :: a
        integer(ip), intent(in) :: n, kl, ku
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: stat
        info = FRIROM_OK
        if (n < 1 .or. kl < 0 .or. ku < 0 .or. kl > n - 1 .or. ku > n - 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'zband_init: need n >= 1 and '// &
                            '0 <= kl, ku <= n-1')
            return
        end if
        if (allocated(a%ab)) deallocate (a%ab)
        if (allocated(a%ipiv)) deallocate (a%ipiv)
        allocate (a%ab(2*kl + ku + 1, n), a%ipiv(n), stat=stat)
        if (stat /= 0) then
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, 'zband_init: banded matrix')
            return
        end if
        a%n = n
        a%kl = kl
        a%ku = ku
        call zband_zero(a)
    end subroutine zband_init

    subroutine zband_zero(a)
        type(zband_matrix), intent(inout) :: a
        a%ab = (0.0_wp, 0.0_wp)
        a%factored = .false.
    end subroutine zband_zero

    pure subroutine zband_add(a, i, j, v, ok)
        type(zband_matrix), intent(inout) :: a
        integer(ip), intent(in) :: i, j
        complex(wp), intent(in) :: v
        logical, intent(inout) :: ok
        if (i - j > a%kl .or. j - i > a%ku) then
            ok = .false.
            return
        end if
        a%ab(a%kl + a%ku + 1 + i - j, j) = a%ab(a%kl + a%ku + 1 + i - j, j) + v
    end subroutine zband_add

    subroutine zband_factor(a, info, errmsg)
        type(zband_matrix), intent(inout) :: a
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: linfo
        character(len=24) :: buf
        info = FRIROM_OK
        call zgbtrf(a%n, a%n, a%kl, a%ku, a%ab, size(a%ab, 1), a%ipiv, linfo)
        if (linfo > 0) then
            write (buf, '(i0)') linfo
            call set_status(info, FRIROM_ERR_SINGULAR, errmsg, 'zgbtrf: zero pivot in row '// &
                            trim(buf)//' (excitation frequency on an undamped resonance?)')
        else if (linfo < 0) then
            write (buf, '(i0)') -linfo
            call set_status(info, FRIROM_ERR_LAPACK, errmsg, 'zgbtrf: illegal argument '// &
                            trim(buf))
        else
            a%factored = .true.
        end if
    end subroutine zband_factor

    subroutine zband_solve(a, b, info, errmsg)
        type(zband_matrix), intent(in) :: a
        complex(wp), intent(inout) :: b(:, :)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer :: linfo
        info = FRIROM_OK
        if (.not. a%factored) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'zband_solve: matrix not factored')
            return
        end if
        if (size(b, 1) /= a%n) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'zband_solve: b has wrong row count')
            return
        end if
        call zgbtrs('N', a%n, a%kl, a%ku, size(b, 2), a%ab, size(a%ab, 1), a%ipiv, b, &
                    size(b, 1), linfo)
        if (linfo /= 0) call set_status(info, FRIROM_ERR_LAPACK, errmsg, &
                                        'zgbtrs: illegal argument')
    end subroutine zband_solve

    !> Half-bandwidth max |p(i) - p(j)| of a symmetric pattern under the ordering `iperm`
    !> (iperm(i) = new position of node i).
    pure function band_width(indptr, indices, iperm) result(bw)
        integer(ip), intent(in) :: indptr(:)   !! (n+1) CSR row pointers, 1-based
        integer(ip), intent(in) :: indices(:)  !! (nnz) column indices, 1-based
        integer(ip), intent(in) :: iperm(:)    !! (n) new position of each node
        integer(ip) :: bw, i, k
        bw = 0
        do i = 1, size(indptr) - 1
            do k = indptr(i), indptr(i + 1) - 1
                bw = max(bw, abs(iperm(i) - iperm(indices(k))))
            end do
        end do
    end function band_width

    !> Reverse Cuthill-McKee ordering of a symmetric graph given as CSR adjacency (self
    !> loops allowed). perm(k) = node placed at position k. Each connected component starts
    !> from a pseudo-peripheral node (repeated breadth-first search from a minimum degree
    !> node); neighbours are visited by increasing degree.
    subroutine rcm_order(indptr, indices, perm, info, errmsg)
        integer(ip), intent(in) :: indptr(:)   !! (n+1) CSR row pointers, 1-based
        integer(ip), intent(in) :: indices(:)  !! (nnz) column indices, 1-based
        integer(ip), intent(out) :: perm(:)    !! (n) new order
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer(ip) :: n, i, k, j, head, tail, start, nnew, pos, ecc, last, tmp
        integer(ip), allocatable :: deg(:), level(:), queue(:), nb(:)
        logical, allocatable :: done(:)
        info = FRIROM_OK
        n = size(indptr) - 1
        if (size(perm) /= n .or. n < 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'rcm_order: perm must have n entries')
            return
        end if
        if (indptr(n + 1) - 1 > size(indices)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, 'rcm_order: indptr exceeds indices')
            return
        end if
        if (any(indices(1:indptr(n + 1) - 1) < 1) .or. &
            any(indices(1:indptr(n + 1) - 1) > n)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'rcm_order: index out of range')
            return
        end if
        allocate (deg(n), level(n), queue(n), nb(n), done(n))
        do i = 1, n
            deg(i) = indptr(i + 1) - indptr(i)
        end do
        done = .false.
        pos = 0
        do while (pos < n)
            ! minimum-degree unvisited node, then walk to a pseudo-peripheral one
            start = 0
            do i = 1, n
                if (.not. done(i)) then
                    if (start == 0) then
                        start = i
                    else if (deg(i) < deg(start)) then
                        start = i
                    end if
                end if
            end do
            ecc = -1
            do
                call bfs_levels(start, last, k)
                if (k <= ecc) exit
                ecc = k
                start = last
            end do
            ! Cuthill-McKee from start
            head = pos + 1
            tail = pos + 1
            perm(tail) = start
            done(start) = .true.
            do while (head <= tail)
                i = perm(head)
                head = head + 1
                nnew = 0
                do k = indptr(i), indptr(i + 1) - 1
                    j = indices(k)
                    if (.not. done(j)) then
                        done(j) = .true.
                        nnew = nnew + 1
                        nb(nnew) = j
                    end if
                end do
                ! insertion sort by degree (neighbour lists are short)
                do k = 2, nnew
                    tmp = nb(k)
                    j = k - 1
                    do while (j >= 1)
                        if (deg(nb(j)) <= deg(tmp)) exit
                        nb(j + 1) = nb(j)
                        j = j - 1
                    end do
                    nb(j + 1) = tmp
                end do
                perm(tail + 1:tail + nnew) = nb(1:nnew)
                tail = tail + nnew
            end do
            pos = tail
        end do
        perm = perm(n:1:-1)

    contains

        !> Breadth-first search from s over unvisited nodes; returns the last node of the
        !> deepest level with the smallest degree and the number of levels.
        subroutine bfs_levels(s, far, nlev)
            integer(ip), intent(in) :: s
            integer(ip), intent(out) :: far, nlev
            integer(ip) :: h, t, u, kk, v
            level = -1
            h = 1
            t = 1
            queue(1) = s
            level(s) = 0
            do while (h <= t)
                u = queue(h)
                h = h + 1
                do kk = indptr(u), indptr(u + 1) - 1
                    v = indices(kk)
                    if (level(v) < 0 .and. .not. done(v)) then
                        level(v) = level(u) + 1
                        t = t + 1
                        queue(t) = v
                    end if
                end do
            end do
            nlev = level(queue(t))
            far = queue(t)
            do kk = t, 1, -1
                if (level(queue(kk)) /= nlev) exit
                if (deg(queue(kk)) < deg(far)) far = queue(kk)
            end do
        end subroutine bfs_levels
    end subroutine rcm_order
end module frirom_banded
