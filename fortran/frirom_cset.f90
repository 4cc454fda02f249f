!> The contact set of a harmonic balance system: its contact groups (law, parameters,
!> AFT workspaces, the stuck stiffness of free bodies), the orbits of a travelling wave,
!> the contacts' G and the user laws' callback. Types only; frirom_hbm (submodule
!> frirom_hbm_contacts) evaluates them.
module frirom_cset
    use frirom_kinds, only: wp, ip
    use frirom_csr, only: csr_matrix
    use frirom_user_law, only: user_law
    implicit none
    private
    public :: contact_group, orbit_group, contact_set

    !> One group of contact elements with the same law, and its AFT workspaces.
    type :: contact_group
        integer(ip) :: law = 0, ne = 0, ndir = 0, row0 = 0  !! row0: rows before it in G
        real(wp), allocatable :: params(:, :)   !! (npar, ne)
        real(wp), allocatable :: w0(:, :)       !! (nslider, ne)
        real(wp), allocatable :: x(:, :, :)     !! (nc, ndir, ne) local displacements
        real(wp), allocatable :: f(:, :, :)     !! (nc, ndir, ne) local forces
        real(wp), allocatable :: jac(:, :, :)   !! (nc ndir, nc ndir, ne)
        real(wp), allocatable :: states(:, :)   !! (3, ne) stick, slip, lift-off fractions
        !> (ne) 2-D law: the period counts held through a corrector (frirom_aft HELD)
        integer(ip), allocatable :: held(:)
        !> (ndir, ne) stuck stiffness moved into K (hbm_free_bodies; unallocated: none)
        !> and the pin on each mean, FREE_PIN ks (0 for a cubic spring)
        real(wp), allocatable :: ks(:, :), kp(:, :)
        !> G x and G^T f of the group: 0 not chosen yet, 1 by its sparse rows, 2 by matrix
        !> products over the columns it reads (rows dense over them: GSI coordinates), 3 by
        !> products per direction (rows dense over the columns that direction reads)
        integer(ip) :: gx_mode = 0
        integer(ip), allocatable :: gcols(:)    !! (ns) the columns it reads (mode 2)
        real(wp), allocatable :: gt(:, :)       !! (ns, ne ndir) its rows of G, transposed
        real(wp), allocatable :: gxs(:, :)      !! (ns, nc) work: x or f on those columns
        !> gx_mode 3 (rows dense over the columns each direction reads: an MS coordinate is
        !> one cylindrical component): dcols(dptr(d):dptr(d+1)-1) the columns direction d
        !> reads, gdt(dptr(d):, :) those of its rows, transposed (stacked, (sum ns_d, ne))
        integer(ip), allocatable :: dcols(:), dptr(:)
        real(wp), allocatable :: gdt(:, :)
        !> gx_mode 3 with a selection (contact_eval's keep): the same per harmonic h and
        !> direction d over the columns kept at h (block d + ndir h of kcols / kptr / gkt),
        !> built for the selection ksel (rebuilt when keep differs)
        integer(ip), allocatable :: kcols(:), kptr(:)
        real(wp), allocatable :: gkt(:, :)
        logical, allocatable :: ksel(:, :)
        !> G^T J_loc G into a dense matrix (assemble_dense): 0 not chosen yet, 1 by the
        !> element loops, 2 by products over gcols / gt; yt, kt its work arrays, kept
        integer(ip) :: asm_mode = 0
        real(wp), allocatable :: yt(:, :), kt(:, :)
    end type contact_group

    !> The orbits of one contact group on a travelling wave (hbm_set_orbits): elements whose
    !> local displacements over the selection's unknowns z are those of a representative
    !> turned in time, G_e T = Rot_e G_r T (harmonic h by h th_e, the same th_e for every
    !> direction), with equal parameters. On the wave their forces are the representative's
    !> turned alike, so the AFT runs on the representatives only and T^T G^T f = sum_r
    !> m_r (G_r T)^T f_r, T^T G^T J G T = sum_r m_r (G_r T)^T J_r (G_r T) (Rot_e orthogonal).
    type :: orbit_group
        integer(ip) :: nrep = 0
        integer(ip), allocatable :: rep(:)          !! (nrep) the representatives' elements
        real(wp), allocatable :: mult(:)            !! (nrep) their orbits' sizes m_r
        real(wp), allocatable :: gz(:, :)           !! (nc ndir nrep, n) G_r T, stacked
        !> work of the representatives' AFT: x, f (nc, ndir, nrep), jac (nc ndir, nc ndir,
        !> nrep), params (npar, nrep), w0 (nslider, nrep), states (3, nrep), y (nc ndir
        !> nrep, n) = m_r J_r G_r T
        real(wp), allocatable :: x(:, :, :), f(:, :, :), jac(:, :, :), params(:, :), &
                                 w0(:, :), states(:, :), y(:, :)
    end type orbit_group

    !> All contact groups; G maps the model's columns (full DoFs or nonlinear DoFs) to the
    !> local relative displacements, rows group by group, element by element, direction.
    !> The forces are relative to rest: the elements' forces at rest f_rest
    !> (law_rest_force: the normal preloads) are left out of the AFT (aft_eval relative),
    !> and G^T f_rest is taken off harmonic 0 of fe0 (hbm_setup). R is the same in exact
    !> arithmetic, but a static load that balances the preloads no longer appears twice,
    !> large, to cancel to rounding (a preload against a soft mount: T D_0^-1 fe huge at
    !> the contacts).
    type :: contact_set
        integer(ip) :: nc = 0
        type(csr_matrix) :: g
        type(contact_group), allocatable :: grp(:)
        !> (ncol) G^T f_rest (hbm_setup); unallocated when no element has a force at rest
        real(wp), allocatable :: c0(:)
        !> the callback of the groups whose law is a user law (negative code; frirom_run
        !> run_set_user_law)
        type(user_law) :: ulaw
        !> the last evaluation's held 2-D history cycles all closed (frirom_aft HELD)
        logical :: settled = .true.
    end type contact_set
end module frirom_cset
