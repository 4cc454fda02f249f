!> Sparse matrices in compressed sparse row form (1-based) for the harmonic balance
!> system: the checked copy a model's K, M, C and G arrive in, y += alpha A x, and
!> coordinate triplets to CSR.
module frirom_csr
    use frirom_kinds, only: wp, ip
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, set_status
    implicit none
    private
    public :: csr_matrix, csr_set, csr_matvec_add, coo_csr

    !> Sparse matrix in compressed sparse row form, 1-based.
    type :: csr_matrix
        integer(ip) :: nrow = 0, ncol = 0
        integer(ip), allocatable :: p(:)   !! (nrow+1) row pointers
        integer(ip), allocatable :: i(:)   !! (nnz) column indices
        real(wp), allocatable :: x(:)      !! (nnz) values
    end type csr_matrix

    !> y += alpha A x for the columns of x (A real, in CSR); x, y and alpha real or
    !> complex (the complex case runs the real kernel on the real and imaginary parts).
    interface csr_matvec_add
        module procedure csr_matvec_add_real, csr_matvec_add_cplx
    end interface csr_matvec_add

contains

    pure subroutine csr_matvec_add_real(a, x, y, alpha)
        type(csr_matrix), intent(in) :: a
        real(wp), intent(in) :: x(:)
        real(wp), intent(inout) :: y(:)
        real(wp), intent(in) :: alpha
        integer(ip) :: i, k
        real(wp) :: s
        do i = 1, a%nrow
            s = 0.0_wp
            do k = a%p(i), a%p(i + 1) - 1
                s = s + a%x(k)*x(a%i(k))
            end do
            y(i) = y(i) + alpha*s
        end do
    end subroutine csr_matvec_add_real

    pure subroutine csr_matvec_add_cplx(a, x, y, alpha)
        type(csr_matrix), intent(in) :: a
        complex(wp), intent(in) :: x(:)
        complex(wp), intent(inout) :: y(:)
        complex(wp), intent(in) :: alpha
        real(wp), allocatable :: sr(:), si(:)
        allocate (sr(a%nrow), si(a%nrow))
        sr = 0.0_wp
        si = 0.0_wp
        call csr_matvec_add_real(a, x%re, sr, 1.0_wp)
        call csr_matvec_add_real(a, x%im, si, 1.0_wp)
        y(:a%nrow) = y(:a%nrow) + alpha*cmplx(sr, si, wp)
    end subroutine csr_matvec_add_cplx

    !> Check and copy a CSR matrix (nrow x ncol, 1-based).
    subroutine csr_set(a, nrow, ncol, p, i, x, name, info, errmsg)
        type(csr_matrix), intent(out) :: a
        integer(ip), intent(in) :: nrow, ncol, p(:), i(:)
        real(wp), intent(in) :: x(:)
        character(len=*), intent(in) :: name
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: nnz, k, bad
        info = FRIROM_OK
        if (size(p) /= nrow + 1) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': row pointer length')
            return
        end if
        nnz = p(nrow + 1) - 1
        if (p(1) /= 1 .or. nnz < 0 .or. nnz > size(i) .or. nnz > size(x) .or. &
            any(p(2:) < p(:nrow))) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': malformed CSR pointers')
            return
        end if
        ! one pass that checks and copies (a reduced model's K, M, C are dense, and set once
        ! per call into Fortran)
        allocate (a%i(nnz), a%x(nnz))
        bad = 0
        do k = 1, nnz
            a%i(k) = i(k)
            a%x(k) = x(k)
            if (i(k) < 1 .or. i(k) > ncol) bad = ior(bad, 1)
            if (.not. abs(x(k)) <= huge(1.0_wp)) bad = ior(bad, 2)
        end do
        if (iand(bad, 1) /= 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': column out of range')
            return
        end if
        if (bad /= 0) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': non-finite value')
            return
        end if
        a%nrow = nrow
        a%ncol = ncol
        a%p = p
    end subroutine csr_set

    !> Coordinate triplets (1-based, duplicates summed) of an nrow x ncol matrix to CSR with
    !> sorted columns; an empty matrix keeps one explicit zero (hbm_setup needs an entry).
    subroutine coo_csr(nrow, ncol, r, c, v, name, p, ci, x, info, errmsg)
        integer(ip), intent(in) :: nrow, ncol, r(:), c(:)
        real(wp), intent(in) :: v(:)
        character(len=*), intent(in) :: name
        integer(ip), allocatable, intent(out) :: p(:), ci(:)
        real(wp), allocatable, intent(out) :: x(:)
        integer(ip), intent(out) :: info
        character(len=*), intent(inout) :: errmsg
        integer(ip) :: k, i, j, q, nz, at(nrow + 1)
        integer(ip), allocatable :: cs(:)
        real(wp), allocatable :: xs(:)
        real(wp) :: tx
        info = FRIROM_OK
        allocate (p(nrow + 1))
        if (size(c) /= size(r) .or. size(v) /= size(r)) then
            call set_status(info, FRIROM_ERR_SIZE, errmsg, name//': rows, columns and values '// &
                            'differ in length')
            return
        end if
        if (any(r < 1) .or. any(r > nrow) .or. any(c < 1) .or. any(c > ncol)) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': an index is out of range')
            return
        end if
        if (.not. all(abs(v) <= huge(1.0_wp))) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, name//': NaN or Inf value')
            return
        end if
        ! counting sort by row, then insertion sort of each row's columns
        at = 0
        do k = 1, size(r)
            at(r(k) + 1) = at(r(k) + 1) + 1
        end do
        at(1) = 1
        do i = 1, nrow
            at(i + 1) = at(i + 1) + at(i)
        end do
        allocate (cs(size(r)), xs(size(r)))
        p = at
        do k = 1, size(r)
            cs(p(r(k))) = c(k)
            xs(p(r(k))) = v(k)
            p(r(k)) = p(r(k)) + 1
        end do
        nz = 0
        p(1) = 1
        do i = 1, nrow
            do k = at(i) + 1, at(i + 1) - 1
                q = cs(k)
                tx = xs(k)
                j = k - 1
                do while (j >= at(i))
                    if (cs(j) <= q) exit
                    cs(j + 1) = cs(j)
                    xs(j + 1) = xs(j)
                    j = j - 1
                end do
                cs(j + 1) = q
                xs(j + 1) = tx
            end do
            do k = at(i), at(i + 1) - 1      ! merge duplicates in place (nz <= k)
                if (nz >= p(i)) then
                    if (cs(nz) == cs(k)) then
                        xs(nz) = xs(nz) + xs(k)
                        cycle
                    end if
                end if
                nz = nz + 1
                cs(nz) = cs(k)
                xs(nz) = xs(k)
            end do
            p(i + 1) = nz + 1
        end do
        if (nz == 0) then
            ci = [1_ip]
            x = [0.0_wp]
        else
            ci = cs(1:nz)
            x = xs(1:nz)
        end if
    end subroutine coo_csr

end module frirom_csr
