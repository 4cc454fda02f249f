!> Every status code has its own message and the unknown code is reported as such.
program test_status
    use frirom_kinds, only: ip
    use frirom_status
    implicit none
    integer(ip), parameter :: codes(*) = [FRIROM_OK, FRIROM_ERR_SIZE, FRIROM_ERR_PARAM, &
        FRIROM_ERR_NONFINITE, FRIROM_ERR_SAMPLES, FRIROM_ERR_ALLOC, FRIROM_ERR_FFTW, &
        FRIROM_ERR_LAPACK, FRIROM_ERR_ARPACK, FRIROM_ERR_NOCONV, FRIROM_ERR_SINGULAR, &
        FRIROM_ERR_LAW, FRIROM_ERR_NOCLOSE, FRIROM_ERR_CONT, FRIROM_ERR_MODEL, FRIROM_ERR_FACTOR]
    integer(ip) :: i, j
    character(len=200) :: msgs(size(codes))
    do i = 1, size(codes)
        msgs(i) = frirom_status_message(codes(i))
        if (msgs(i) == 'unknown status code') error stop 'a status code has no message'
        do j = 1, i - 1
            if (codes(i) == codes(j)) error stop 'two status codes share a value'
            if (msgs(i) == msgs(j)) error stop 'two status codes share a message'
        end do
    end do
    if (frirom_status_message(999_ip) /= 'unknown status code') error stop 'code 999 known?'
    print '(a)', 'test_status: ok'
end program test_status
