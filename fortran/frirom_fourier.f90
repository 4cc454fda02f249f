!> FFTW plans and the maps between real harmonic coefficients and time samples.
!>
!> Harmonic ordering everywhere in frirom: for H harmonics, 2H+1 real coefficients
!> [a0, a1, b1, a2, b2, ..., aH, bH] with x(tau) = a0 + sum_h a_h cos(h tau) + b_h sin(h tau),
!> tau = omega t, sampled at tau_k = 2 pi (k-1) / N, k = 1..N.
!>
!> A fourier_plan transforms batches of `nbatch` signals per "slot" with one FFTW plan per
!> direction, made once. Signals of a batch are interleaved (sample k of signal j at
!> (j, k)), so that a contact law marches all elements of a batch together, sample after
!> sample, with independent slider recurrences side by side (SIMD, no latency chain).
!> The plan owns its buffers (FFTW-aligned), so it must not be copied: create, use, destroy.
module frirom_fourier
    use, intrinsic :: iso_c_binding
    use frirom_kinds, only: wp, ip
    use frirom_lapack, only: dgemm
    use frirom_status, only: FRIROM_OK, FRIROM_ERR_SAMPLES, FRIROM_ERR_PARAM, &
                             FRIROM_ERR_FFTW, FRIROM_ERR_ALLOC, set_status
    implicit none
    private
    include 'fftw3.f03'

    public :: fourier_plan, fourier_plan_create, fourier_plan_destroy
    public :: clear_input, load_harmonics, exec_c2r, exec_r2c, harmonics_of, trig_sums, &
              toeplitz_add
    public :: segment_sum, run_trig_sums, synth_direct, analyse_direct

    !> Harmonics up to which the AFT transforms by the trigonometric tables (O(N (2H+1)) per
    !> signal, vectorised over the batch) instead of FFTW (O(N log N) with per-call overhead
    !> and all N/2 harmonics): faster at the few harmonics friction models use
    !> (cases/bench/aft.py, H = 1-7).
    integer(ip), parameter, public :: DIRECT_MAX_HARM = 8

    !> Batched real FFTs of length N plus the trigonometric tables of H harmonics.
    type :: fourier_plan
        integer(ip) :: nharm = -1    !! H, number of harmonics above the mean
        integer(ip) :: nsamp = 0     !! N, time samples per period
        integer(ip) :: ncoef = 0     !! 2H+1
        integer(ip) :: nbatch = 0    !! signals per slot transformed by one FFTW call
        integer(ip) :: nslot_in = 0  !! slots of harmonic -> time transforms
        integer(ip) :: nslot_out = 0 !! slots of time -> harmonic transforms
        type(c_ptr) :: p_c2r = c_null_ptr, p_r2c = c_null_ptr
        type(c_ptr) :: m_rin = c_null_ptr, m_cin = c_null_ptr
        type(c_ptr) :: m_rout = c_null_ptr, m_cout = c_null_ptr
        real(c_double), pointer, contiguous :: rin(:, :, :) => null()  !! (nbatch, N, nslot_in)
        !> (nbatch, N/2+1, .)
        complex(c_double_complex), pointer, contiguous :: cin(:, :, :) => null()
        real(c_double), pointer, contiguous :: rout(:, :, :) => null() !! (nbatch, N, nslot_out)
        complex(c_double_complex), pointer, contiguous :: cout(:, :, :) => null()
        real(wp), allocatable :: basis(:, :)   !! (N, 2H+1): row k = [1, cos tau_k, sin tau_k, ...]
        real(wp), allocatable :: weight(:)     !! (2H+1): 1/N for a0, 2/N for the others
        real(wp), allocatable :: prefix(:, :)  !! (4H+1, 0:N): running sums over the samples of
                                               !! [1, cos tau, sin tau, .., cos 2H tau, sin 2H tau]
        logical :: direct = .false.            !! transform by the tables (H <= DIRECT_MAX_HARM)
        real(wp), allocatable :: coef(:, :)    !! (nbatch, 2H+1) one slot's harmonics, batch-major
    end type fourier_plan

contains

    !> Make the FFTW plans and tables for H harmonics and N samples.
    !> N >= 2H+1 is required (fewer samples alias harmonic H onto lower ones).
    subroutine fourier_plan_create(plan, nharm, nsamp, nbatch, nslot_in, nslot_out, &
                                   measure, info, errmsg)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: nharm      !! H >= 0
        integer(ip), intent(in) :: nsamp      !! N >= 2H+1
        integer(ip), intent(in) :: nbatch     !! signals per slot (>= 1; rounded up to even)
        integer(ip), intent(in) :: nslot_in   !! input slots (>= 1)
        integer(ip), intent(in) :: nslot_out  !! output slots (>= 1)
        logical, intent(in) :: measure        !! FFTW_MEASURE instead of FFTW_ESTIMATE
        integer(ip), intent(out) :: info
        character(len=*), intent(inout), optional :: errmsg
        integer(c_int) :: n(1), nembed_c(1), flags, nb
        logical :: aligned
        integer(ip) :: k, h, nc, nhalf, stat
        real(wp) :: tau
        character(len=80) :: buf

        call fourier_plan_destroy(plan)
        info = FRIROM_OK
        if (nharm < 0) then
            write (buf, '(a,i0)') 'number of harmonics H must be >= 0, got ', nharm
            call set_status(info, FRIROM_ERR_PARAM, errmsg, trim(buf))
            return
        end if
        if (nsamp < 2*nharm + 1) then
            write (buf, '(a,i0,a,i0,a,i0)') 'N = ', nsamp, ' samples for H = ', nharm, &
                ': need N >= 2H+1 = ', 2*nharm + 1
            call set_status(info, FRIROM_ERR_SAMPLES, errmsg, trim(buf))
            return
        end if
        if (nbatch < 1 .or. nslot_in < 1 .or. nslot_out < 1) then
            call set_status(info, FRIROM_ERR_PARAM, errmsg, 'batch and slot counts must be >= 1')
            return
        end if
        nc = 2*nharm + 1
        nhalf = nsamp/2 + 1
        plan%nharm = nharm
        plan%nsamp = nsamp
        plan%ncoef = nc
        plan%nbatch = nbatch + mod(nbatch, 2)
        plan%nslot_in = nslot_in
        plan%nslot_out = nslot_out

        plan%m_rin = fftw_alloc_real(int(nsamp, c_size_t)*plan%nbatch*nslot_in)
        plan%m_cin = fftw_alloc_complex(int(nhalf, c_size_t)*plan%nbatch*nslot_in)
        plan%m_rout = fftw_alloc_real(int(nsamp, c_size_t)*plan%nbatch*nslot_out)
        plan%m_cout = fftw_alloc_complex(int(nhalf, c_size_t)*plan%nbatch*nslot_out)
        if (.not. (c_associated(plan%m_rin) .and. c_associated(plan%m_cin) .and. &
                   c_associated(plan%m_rout) .and. c_associated(plan%m_cout))) then
            call fourier_plan_destroy(plan)
            write (buf, '(a,i0,a,i0,a)') 'fftw_alloc failed: no memory, N = ', &
                nsamp, ' samples x ', nbatch, ' signals'
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, trim(buf))
            return
        end if
        call c_f_pointer(plan%m_rin, plan%rin, [plan%nbatch, nsamp, nslot_in])
        call c_f_pointer(plan%m_cin, plan%cin, [plan%nbatch, nhalf, nslot_in])
        call c_f_pointer(plan%m_rout, plan%rout, [plan%nbatch, nsamp, nslot_out])
        call c_f_pointer(plan%m_cout, plan%cout, [plan%nbatch, nhalf, nslot_out])

        flags = FFTW_ESTIMATE
        if (measure) flags = FFTW_MEASURE
        n(1) = int(nsamp, c_int)
        nembed_c(1) = int(nhalf, c_int)
        nb = int(plan%nbatch, c_int)
        ! Slot 1 is the planning array; the others start an even number of doubles further
        ! on (nbatch is even), so they share its SIMD alignment (checked below). Stride
        ! nbatch between samples, distance 1 between signals: the interleaved layout.
        plan%p_c2r = fftw_plan_many_dft_c2r(1_c_int, n, nb, plan%cin(:, :, 1), nembed_c, nb, &
                                            1_c_int, plan%rin(:, :, 1), n, nb, 1_c_int, flags)
        plan%p_r2c = fftw_plan_many_dft_r2c(1_c_int, n, nb, plan%rout(:, :, 1), n, nb, 1_c_int, &
                                            plan%cout(:, :, 1), nembed_c, nb, 1_c_int, flags)
        aligned = slot_alignment_ok(plan)
        if (.not. c_associated(plan%p_c2r) .or. .not. c_associated(plan%p_r2c) .or. &
            .not. aligned) then
            call fourier_plan_destroy(plan)
            call set_status(info, FRIROM_ERR_FFTW, errmsg, 'fftw_plan_many_dft (c2r/r2c)')
            return
        end if
        plan%rin = 0.0_wp
        plan%rout = 0.0_wp
        plan%cin = (0.0_wp, 0.0_wp)
        plan%cout = (0.0_wp, 0.0_wp)

        plan%direct = nharm <= DIRECT_MAX_HARM
        allocate (plan%coef(plan%nbatch, nc), plan%basis(nsamp, nc), plan%weight(nc), &
                  plan%prefix(4*nharm + 1, 0:nsamp), stat=stat)
        if (stat /= 0) then
            call fourier_plan_destroy(plan)
            write (buf, '(a,i0,a,i0)') 'allocate failed: no memory, N = ', nsamp, &
                ' samples, H = ', nharm
            call set_status(info, FRIROM_ERR_ALLOC, errmsg, trim(buf))
            return
        end if
        do k = 1, nsamp
            tau = 2.0_wp*acos(-1.0_wp)*real(k - 1, wp)/real(nsamp, wp)
            plan%basis(k, 1) = 1.0_wp
            do h = 1, nharm
                plan%basis(k, 2*h) = cos(real(h, wp)*tau)
                plan%basis(k, 2*h + 1) = sin(real(h, wp)*tau)
            end do
        end do
        plan%weight = 2.0_wp/real(nsamp, wp)
        plan%weight(1) = 1.0_wp/real(nsamp, wp)
        plan%prefix(:, 0) = 0.0_wp
        do k = 1, nsamp
            tau = 2.0_wp*acos(-1.0_wp)*real(k - 1, wp)/real(nsamp, wp)
            plan%prefix(1, k) = plan%prefix(1, k - 1) + 1.0_wp
            do h = 1, 2*nharm
                plan%prefix(2*h, k) = plan%prefix(2*h, k - 1) + cos(real(h, wp)*tau)
                plan%prefix(2*h + 1, k) = plan%prefix(2*h + 1, k - 1) + sin(real(h, wp)*tau)
            end do
        end do
    end subroutine fourier_plan_create

    !> Every slot must have the alignment of slot 1, the array FFTW planned on (the
    !> new-array execute functions require it). Complex slots are 16-byte multiples apart
    !> by construction; the real ones are checked.
    logical function slot_alignment_ok(plan) result(ok)
        type(fourier_plan), intent(inout) :: plan
        integer(ip) :: s
        integer(c_int) :: a1, a2
        ok = .true.
        a1 = fftw_alignment_of(plan%rin(:, 1, 1))
        do s = 2, plan%nslot_in
            a2 = fftw_alignment_of(plan%rin(:, 1, s))
            if (a2 /= a1) ok = .false.
        end do
        a1 = fftw_alignment_of(plan%rout(:, 1, 1))
        do s = 2, plan%nslot_out
            a2 = fftw_alignment_of(plan%rout(:, 1, s))
            if (a2 /= a1) ok = .false.
        end do
    end function slot_alignment_ok

    !> Free the plans and buffers; safe on a plan never created.
    subroutine fourier_plan_destroy(plan)
        type(fourier_plan), intent(inout) :: plan
        if (c_associated(plan%p_c2r)) call fftw_destroy_plan(plan%p_c2r)
        if (c_associated(plan%p_r2c)) call fftw_destroy_plan(plan%p_r2c)
        if (c_associated(plan%m_rin)) call fftw_free(plan%m_rin)
        if (c_associated(plan%m_cin)) call fftw_free(plan%m_cin)
        if (c_associated(plan%m_rout)) call fftw_free(plan%m_rout)
        if (c_associated(plan%m_cout)) call fftw_free(plan%m_cout)
        plan%p_c2r = c_null_ptr
        plan%p_r2c = c_null_ptr
        plan%m_rin = c_null_ptr
        plan%m_cin = c_null_ptr
        plan%m_rout = c_null_ptr
        plan%m_cout = c_null_ptr
        nullify (plan%rin, plan%cin, plan%rout, plan%cout)
        if (allocated(plan%basis)) deallocate (plan%basis)
        if (allocated(plan%coef)) deallocate (plan%coef)
        if (allocated(plan%weight)) deallocate (plan%weight)
        if (allocated(plan%prefix)) deallocate (plan%prefix)
        plan%nharm = -1
        plan%nsamp = 0
        plan%ncoef = 0
    end subroutine fourier_plan_destroy

    !> Put the harmonic coefficients of signal `col` into input slot `slot`.
    subroutine load_harmonics(plan, slot, col, xh)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot, col
        real(wp), intent(in) :: xh(:)  !! (2H+1) [a0, a1, b1, ...]
        integer(ip) :: h
        ! c2r computes y_k = Y_0 + 2 Re sum_h Y_h exp(i h tau_k): Y_h = (a_h - i b_h)/2.
        ! Entries above H must be zero: clear_input clears the slot (c2r destroys its input).
        plan%cin(col, 1, slot) = cmplx(xh(1), 0.0_wp, wp)
        do h = 1, plan%nharm
            plan%cin(col, h + 1, slot) = cmplx(0.5_wp*xh(2*h), -0.5_wp*xh(2*h + 1), wp)
        end do
    end subroutine load_harmonics

    !> Harmonics -> time samples of the first m signals of input slot `slot` by the basis
    !> table: rin(j, k) = sum_c coef(j, c) basis(k, c), coef(1:m, :) filled by the caller
    !> (row j: [a0, a1, b1, ..] of signal j). Same result as load_harmonics + exec_c2r to
    !> rounding; no FFTW call and no clearing.
    subroutine synth_direct(plan, slot, m)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot, m
        call dgemm('N', 'T', m, plan%nsamp, plan%ncoef, 1.0_wp, plan%coef, plan%nbatch, &
                   plan%basis, plan%nsamp, 0.0_wp, plan%rin(:, :, slot), plan%nbatch)
    end subroutine synth_direct

    !> Time samples -> harmonics of the first m signals of output slot `slot` by the basis
    !> table: coef(j, c) = weight(c) sum_k rout(j, k) basis(k, c) (the exact DFT of the
    !> retained harmonics; exec_r2c + harmonics_of give the same to rounding).
    subroutine analyse_direct(plan, slot, m)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot, m
        integer(ip) :: c
        call dgemm('N', 'N', m, plan%ncoef, plan%nsamp, 1.0_wp, plan%rout(:, :, slot), &
                   plan%nbatch, plan%basis, plan%nsamp, 0.0_wp, plan%coef, plan%nbatch)
        do c = 1, plan%ncoef
            plan%coef(1:m, c) = plan%weight(c)*plan%coef(1:m, c)
        end do
    end subroutine analyse_direct

    !> Zero the spectra of input slot `slot` before load_harmonics fills a new batch.
    pure subroutine clear_input(plan, slot)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot
        plan%cin(:, :, slot) = (0.0_wp, 0.0_wp)
    end subroutine clear_input

    !> Harmonics -> time samples for every signal of input slot `slot` (into rin).
    subroutine exec_c2r(plan, slot)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot
        call fftw_execute_dft_c2r(plan%p_c2r, plan%cin(:, :, slot), plan%rin(:, :, slot))
    end subroutine exec_c2r

    !> Time samples (rout) -> spectra (cout) for every signal of output slot `slot`.
    subroutine exec_r2c(plan, slot)
        type(fourier_plan), intent(inout) :: plan
        integer(ip), intent(in) :: slot
        call fftw_execute_dft_r2c(plan%p_r2c, plan%rout(:, :, slot), plan%cout(:, :, slot))
    end subroutine exec_r2c

    !> Real harmonic coefficients of signal `col` of output slot `slot` (after exec_r2c).
    pure subroutine harmonics_of(plan, slot, col, xh)
        type(fourier_plan), intent(in) :: plan
        integer(ip), intent(in) :: slot, col
        real(wp), intent(out) :: xh(:)  !! (2H+1)
        integer(ip) :: h
        real(wp) :: s
        s = 2.0_wp/real(plan%nsamp, wp)
        xh(1) = real(plan%cout(col, 1, slot), wp)/real(plan%nsamp, wp)
        do h = 1, plan%nharm
            xh(2*h) = s*real(plan%cout(col, h + 1, slot), wp)
            xh(2*h + 1) = -s*aimag(plan%cout(col, h + 1, slot))
        end do
    end subroutine harmonics_of

    !> C_m = sum_k c_k cos(m tau_k), S_m = sum_k c_k sin(m tau_k), m = 0..2H, of the time
    !> series `col` of output slot `slot` (after exec_r2c). Exact for any m: the
    !> spectrum is N-periodic in m and Hermitian.
    pure subroutine trig_sums(plan, slot, col, cm, sm)
        type(fourier_plan), intent(in) :: plan
        integer(ip), intent(in) :: slot, col
        real(wp), intent(out) :: cm(0:), sm(0:)  !! (0:2H)
        integer(ip) :: m, mm, n
        n = plan%nsamp
        do m = 0, 2*plan%nharm
            mm = mod(m, n)
            if (mm <= n/2) then
                cm(m) = real(plan%cout(col, mm + 1, slot), wp)
                sm(m) = -aimag(plan%cout(col, mm + 1, slot))
            else
                cm(m) = real(plan%cout(col, n - mm + 1, slot), wp)
                sm(m) = aimag(plan%cout(col, n - mm + 1, slot))
            end if
        end do
    end subroutine trig_sums

    !> J(r0+1:r0+2H+1, c0+1:c0+2H+1) += T, the harmonic matrix of multiplication by a time
    !> series c: T(i,j) = sum_k P(i,k) c_k E(k,j) with E the basis and P the analysis map.
    !> Built from the trig sums of c by the product-to-sum identities: O(H^2), no O(N) work.
    pure subroutine toeplitz_add(nharm, nsamp, cm, sm, jac, r0, c0)
        integer(ip), intent(in) :: nharm, nsamp
        real(wp), intent(in) :: cm(0:), sm(0:)  !! trig sums of c, m = 0..2H
        real(wp), intent(inout) :: jac(:, :)
        integer(ip), intent(in) :: r0, c0     !! row and column offsets of the block
        integer(ip) :: h, l, d
        real(wp) :: rn, sd
        rn = 1.0_wp/real(nsamp, wp)
        jac(r0 + 1, c0 + 1) = jac(r0 + 1, c0 + 1) + rn*cm(0)
        do l = 1, nharm
            jac(r0 + 1, c0 + 2*l) = jac(r0 + 1, c0 + 2*l) + rn*cm(l)
            jac(r0 + 1, c0 + 2*l + 1) = jac(r0 + 1, c0 + 2*l + 1) + rn*sm(l)
        end do
        do h = 1, nharm
            jac(r0 + 2*h, c0 + 1) = jac(r0 + 2*h, c0 + 1) + 2.0_wp*rn*cm(h)
            jac(r0 + 2*h + 1, c0 + 1) = jac(r0 + 2*h + 1, c0 + 1) + 2.0_wp*rn*sm(h)
            do l = 1, nharm
                d = abs(h - l)
                sd = sign(1.0_wp, real(h - l, wp))*sm(d)  ! S_{h-l}, odd in its index
                jac(r0 + 2*h, c0 + 2*l) = jac(r0 + 2*h, c0 + 2*l) + rn*(cm(d) + cm(h + l))
                jac(r0 + 2*h, c0 + 2*l + 1) = jac(r0 + 2*h, c0 + 2*l + 1) + rn*(sm(h + l) - sd)
                jac(r0 + 2*h + 1, c0 + 2*l) = jac(r0 + 2*h + 1, c0 + 2*l) + rn*(sm(h + l) + sd)
                jac(r0 + 2*h + 1, c0 + 2*l + 1) = jac(r0 + 2*h + 1, c0 + 2*l + 1) &
                                                  + rn*(cm(d) - cm(h + l))
            end do
        end do
    end subroutine toeplitz_add

    !> Weighted sum of the basis rows over the cyclic sample range i1..i2 (inclusive):
    !> g = sum_k P(:, k), the analysis of a unit series on that range.
    pure subroutine segment_sum(plan, i1, i2, g)
        type(fourier_plan), intent(in) :: plan
        integer(ip), intent(in) :: i1, i2
        real(wp), intent(out) :: g(:)  !! (2H+1)
        integer(ip) :: nc
        nc = plan%ncoef
        if (i1 <= i2) then
            g = plan%prefix(1:nc, i2) - plan%prefix(1:nc, i1 - 1)
        else
            g = plan%prefix(1:nc, plan%nsamp) - plan%prefix(1:nc, i1 - 1) + plan%prefix(1:nc, i2)
        end if
        g = g*plan%weight
    end subroutine segment_sum

    !> Trig sums C_m, S_m (m = 0..2H) of a sampled series c(1:N) by runs of equal values:
    !> each run costs O(H) through the prefix table, so a piecewise-constant series (the
    !> stick, slip and contact coefficients of a friction law) needs no transform at all.
    !> A series without runs degrades gracefully to the direct O(N H) sum.
    pure subroutine run_trig_sums(plan, c, cm, sm)
        type(fourier_plan), intent(in) :: plan
        real(wp), intent(in) :: c(:)             !! (N) the series
        real(wp), intent(out) :: cm(0:), sm(0:)  !! (0:2H)
        integer(ip) :: k, k0, n, m
        real(wp) :: val
        n = plan%nsamp
        cm = 0.0_wp
        sm = 0.0_wp
        k0 = 1
        do k = 2, n + 1
            if (k <= n) then
                if (c(k) == c(k0)) cycle
            end if
            val = c(k0)
            if (val /= 0.0_wp) then
                cm(0) = cm(0) + val*real(k - k0, wp)
                do m = 1, 2*plan%nharm
                    cm(m) = cm(m) + val*(plan%prefix(2*m, k - 1) - plan%prefix(2*m, k0 - 1))
                    sm(m) = sm(m) + val*(plan%prefix(2*m + 1, k - 1) &
                                         - plan%prefix(2*m + 1, k0 - 1))
                end do
            end if
            k0 = k
        end do
    end subroutine run_trig_sums
end module frirom_fourier
