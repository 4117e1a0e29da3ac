"""Symbolic cable model of sagcal: catenary, cable geometry and statics (paper Sec. III).

Pure symbolic functions, no code generation here. ``factors.py`` builds the
residuals from them and ``generate.py`` emits Rust. Equation numbers refer to
Dindarloo et al., *A Graph-Based Self-Calibration Technique for Cable-Driven
Robots with Sagging Cable* (``shared/paper``).

Conventions (identical to the hand-written Rust in ``src/model``):

* A pose is ``world_from_platform = (R, p)``; an attachment point ``b`` given in
  the platform frame is at ``p + R b`` in the world frame.
* Each cable hangs in the vertical plane through its anchor ``a`` (pulley exit,
  world frame) and its attachment. In that plane ``x`` runs horizontally from
  the anchor towards the attachment over the span ``L = ||(p + R b - a)_xy||``.
* ``f_h > 0`` is the horizontal tension, ``f_v`` the vertical tension at the
  attachment, positive when the cable pulls the platform up. The force of the
  cable on the platform is ``-s f_h + z f_v`` with ``s`` the horizontal unit
  vector from the anchor to the attachment and ``z`` the world's up axis.
* Every function that can divide by zero or take a square root at zero takes
  an explicit ``epsilon`` (a small positive number at run time, e.g.
  ``10 * f64::EPSILON``, SymForce's default).

Intermediate quantities are marked with ``forward_mode.checkpoint`` (and
``rotation_matrix``, ``linear_solution``): the marks change nothing in the
values, they tell ``generate.py`` where to apply the chain rule (see
``forward_mode.py``), which halves the operations of the generated Jacobians.

The cable's material enters only through :class:`CableProperties`, which the
catenary functions take as an argument: an elastic cable (Irvine's elastic
catenary, axial stiffness ``EA``) or a pulley radius become new fields there
and new terms in :func:`catenary_length` / :func:`catenary_drop`, without
touching the geometry, the statics or the residuals.
"""

from __future__ import annotations

import dataclasses

import symforce

# generate.py calls this first; every function here takes `epsilon` explicitly anyway.
try:
    symforce.set_epsilon_to_symbol()
except symforce.AlreadyUsedEpsilon:
    pass

import symforce.symbolic as sf  # noqa: E402  (must follow set_epsilon_to_symbol)

from forward_mode import checkpoint, linear_solution, rotation_matrix  # noqa: E402

# Number of cables of the suspended robot, and the slot of the reference cable.
CABLE_COUNT = 4
REFERENCE_SLOT = 0

UP = sf.V3(0, 0, 1)


@dataclasses.dataclass(frozen=True)
class CableProperties:
    """Physical properties of a cable, shared by the four cables of the robot.

    Attributes:
        weight_n_per_m: Cable weight per unit length ``g_c = rho_c g`` in N/m (paper
            Sec. III-B, after eq. 3); 0 gives the massless straight cable.

    Later models add fields here (each with a neutral default, so existing
    residuals keep their meaning): ``axial_stiffness_n`` (``EA``) for Irvine's
    elastic catenary, which adds ``f_h L / EA``-type stretch terms to the length
    and the drop, and ``pulley_radius_m`` for the wrap of the cable around the
    pulley, which moves the effective anchor.
    """

    weight_n_per_m: sf.Scalar


@dataclasses.dataclass(frozen=True)
class CableExtensions:
    """The physical effects of the extended model (``sagcal diagnose``, issue 4), all neutral at 0.

    Attributes:
        axial_compliance_per_n: ``1 / EA`` of every cable, 1/N (Irvine's elastic
            catenary, :func:`elastic_free_length`); 0: inextensible.
        pulley_radius_m: Radius ``r`` of the swivelling pulley at every anchor, metres
            (:func:`pulley_exit`); 0: the cable leaves at the anchor point.
        inverse_segments_squared: ``1/n^2`` for a cable modelled as a chain of
            ``n`` straight elements (:func:`segmented_chain`); 0: the smooth cable.
    """

    axial_compliance_per_n: sf.Scalar
    pulley_radius_m: sf.Scalar
    inverse_segments_squared: sf.Scalar = 0


def top_tension(
    free_length_m: sf.Scalar, horizontal_tension_n: sf.Scalar, vertical_tension_n: sf.Scalar, cable: CableProperties
) -> tuple[sf.Scalar, sf.Scalar]:
    """Vertical tension and tension magnitude at the upper end of a hanging cable.

    The vertical force grows by the weight of the cable below (paper eq. 1-3:
    ``T_v(s) = f_v + g_c s`` along the arc from the attachment), so at the top
    ``V_top = f_v + g_c l`` and ``T_top = sqrt(f_h^2 + V_top^2)`` (``f_h > 0``
    keeps the root away from zero).

    Args:
        free_length_m: Arc length ``l`` of the hanging cable, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable: The cable's properties (``g_c``).

    Returns:
        ``(V_top, T_top)`` in newtons.
    """
    v_top = vertical_tension_n + cable.weight_n_per_m * free_length_m
    return v_top, sf.sqrt(horizontal_tension_n**2 + v_top**2)


def pulley_exit(
    anchor_span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    pulley_radius_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> tuple[sf.Scalar, sf.Scalar, sf.Scalar]:
    """Where the cable leaves a swivelling pulley of radius ``r`` (pulley wrap geometry).

    The pulley swivels about the vertical axis through the anchor ``a``; the
    cable comes up that axis, enters the groove at ``a``, wraps over the top and
    leaves tangentially towards the platform (the geometry of
    ``src/sim/discretised.rs``). In the cable's vertical plane, with ``s`` the
    horizontal direction towards the attachment and the cable leaving along the
    top tension ``(-f_h s, V_top) / T_top`` (:func:`top_tension`), the circle's
    tangent point is::

        e = a + r [ (1 + c) s + h z ],   c = V_top / T_top,  h = f_h / T_top
        wrap = pi - atan2(f_h, V_top) = pi/2 + atan(V_top / f_h)

    The top tension depends on the free length, which depends on the exit
    point; two fixed-point passes starting from the anchor (``r = 0``) leave an
    error of order ``r (g_c r / T)^2``, far below a micrometre for these robots.

    Args:
        anchor_span_m: Horizontal span from the anchor to the attachment, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable: The cable's properties (``g_c``).
        pulley_radius_m: ``r``, metres (0: the exit point is the anchor).
        epsilon: Small positive number.

    Returns:
        ``(span, rise, wrap)``: the horizontal span from the exit point to the
        attachment (m), the exit point's height above the anchor (m) and the
        wrap angle (rad).
    """
    span = anchor_span_m
    v_top = vertical_tension_n
    t_top = sf.sqrt(horizontal_tension_n**2 + v_top**2)
    for _ in range(2):
        free_length = catenary_length(span, horizontal_tension_n, vertical_tension_n, cable, epsilon)
        v_top, t_top = top_tension(free_length, horizontal_tension_n, vertical_tension_n, cable)
        span = anchor_span_m - pulley_radius_m * (1 + v_top / t_top)
    wrap = sf.pi / 2 + sf.atan(v_top / horizontal_tension_n)
    return span, pulley_radius_m * horizontal_tension_n / t_top, wrap


def elastic_free_length(
    span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    axial_compliance_per_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> tuple[sf.Scalar, sf.Scalar, sf.Scalar]:
    """Unstretched length and drop of an elastic catenary, first order in ``1/EA`` (Irvine).

    Irvine's elastic catenary (*Cable Structures*, 1981, eq. 2.23-2.24), with
    the arc coordinate ``s`` of the unstretched cable (length ``L0``, weight
    ``g_c`` per unstretched metre) measured from the attachment, end forces
    ``f_h, f_v`` there and ``k = 1/EA``::

        span(L0) = k f_h L0 + X(L0),   rise(L0) = k (f_v L0 + g_c L0^2 / 2) + Z(L0)

    where ``X``, ``Z`` are the inextensible catenary's. For the span ``L`` of the
    geometry, ``X(l) = L`` at the inextensible length ``l`` (:func:`catenary_length`);
    one Newton step in ``L0`` (``X' = f_h / T_top``, ``Z' = V_top / T_top``) gives::

        L0   = l (1 - k T_top) + O(k^2)
        drop = drop_inextensible(L) - k g_c l^2 / 2 + O(k^2)

    For a massless cable this is the spring ``L0 = l / (1 + k T)`` to first
    order; the neglected term is ``l (k T)^2``, 1e-5 m for a 20 m cable at
    ``T / EA = 1e-3``.

    Args:
        span_m: Horizontal span from the cable's upper end to the attachment, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable: The cable's properties (``g_c``).
        axial_compliance_per_n: ``k = 1/EA``, 1/N (0: inextensible).
        epsilon: Small positive number.

    Returns:
        ``(L0, drop, T_top)``: the unstretched free length (m), the upper end's
        height above the attachment (m) and the tension at the upper end (N).
    """
    free_length = catenary_length(span_m, horizontal_tension_n, vertical_tension_n, cable, epsilon)
    drop = catenary_drop(span_m, horizontal_tension_n, vertical_tension_n, cable, epsilon)
    _, t_top = top_tension(free_length, horizontal_tension_n, vertical_tension_n, cable)
    unstretched = free_length * (1 - axial_compliance_per_n * t_top)
    drop = drop - axial_compliance_per_n * cable.weight_n_per_m * free_length**2 / 2
    return unstretched, drop, t_top


def segmented_chain(
    span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    inverse_segments_squared: sf.Scalar,
    epsilon: sf.Scalar,
) -> tuple[sf.Scalar, sf.Scalar]:
    """Length and drop of a chain of ``n`` straight elements minus the smooth catenary's, to order ``1/n^2``.

    A finite-element cable of ``n`` equal straight elements of length
    ``h = l/n`` with lumped node weights (``g_c h`` inside, half at each end;
    the chain of ``src/sim/discretised.rs``) carries in element ``k`` the
    vertical force ``V(s_k) = f_v + g_c s_k`` at the element's midpoint
    ``s_k = (k + 1/2) h``. Its end-to-end span and rise are therefore the
    midpoint rule applied to the smooth catenary's integrals
    ``X(l) = int_0^l f_h/T ds`` and ``Z(l) = int_0^l V/T ds``
    (``T = sqrt(f_h^2 + V^2)``), whose error is, by the Euler-Maclaurin
    formula, ``int f - M(f) = h^2/24 [f']_0^l + O(h^4)``::

        E_x = -(h^2 g_c f_h / 24) [V/T^3]_0^l,   E_z = (h^2 g_c f_h^2 / 24) [1/T^3]_0^l

    The chain spanning the same ``L`` at the same end forces is longer than
    the smooth cable ``l`` by ``dl = E_x / X'(l) = E_x T_top / f_h`` and
    rises ``dz = (V_top / T_top) dl - E_z`` more. Both vanish as ``1/n^2``
    (``h^2 = l^2 / n^2``); for a shallow cable ``dl`` reduces to the chord
    deficit ``-(h^2/24) int kappa^2 ds`` of a polygon inscribed in the arc.

    Args:
        span_m: Horizontal span ``L`` from the cable's upper end to the attachment, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable: The cable's properties (``g_c``).
        inverse_segments_squared: ``1/n^2`` (0: the smooth cable).
        epsilon: Small positive number.

    Returns:
        ``(dl, dz)``: the chain's length and drop minus the smooth cable's, metres.
    """
    free_length = catenary_length(span_m, horizontal_tension_n, vertical_tension_n, cable, epsilon)
    v_top, t_top = top_tension(free_length, horizontal_tension_n, vertical_tension_n, cable)
    t_bottom = sf.sqrt(horizontal_tension_n**2 + vertical_tension_n**2)
    element_squared = free_length**2 * inverse_segments_squared
    g = cable.weight_n_per_m
    error_x = -element_squared * g * horizontal_tension_n / 24 * (
        v_top / t_top**3 - vertical_tension_n / t_bottom**3
    )
    error_z = element_squared * g * horizontal_tension_n**2 / 24 * (1 / t_top**3 - 1 / t_bottom**3)
    length_change = error_x * t_top / horizontal_tension_n
    return length_change, v_top / t_top * length_change - error_z


def extended_cable(
    anchor_span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    extensions: CableExtensions,
    epsilon: sf.Scalar,
) -> tuple[sf.Scalar, sf.Scalar]:
    """Paid-out length and drop of a cable with pulley wrap, elasticity and finite elements.

    The free span runs from the pulley exit point (:func:`pulley_exit`) to the
    attachment as an elastic catenary (:func:`elastic_free_length`), or as a
    chain of ``n`` straight elements (:func:`segmented_chain`, first order in
    ``1/n^2``; the cross terms with ``k`` are of order ``k/n^2``); the drum
    pays out the free cable plus the arc on the groove, which is under the top
    tension: ``paid_out = L0 + dl + r wrap / (1 + k T_top)``. With ``r = 0``,
    ``k = 0`` and ``1/n^2 = 0`` this is exactly :func:`catenary_length` and
    :func:`catenary_drop`.

    Args:
        anchor_span_m: Horizontal span from the anchor to the attachment, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable: The cable's properties (``g_c``).
        extensions: Compliance, pulley radius and ``1/n^2``.
        epsilon: Small positive number.

    Returns:
        ``(paid_out, drop)``: the length paid out past the anchor (m) and the
        anchor's height above the attachment implied by the cable (m).
    """
    radius = extensions.pulley_radius_m
    span, rise, wrap = pulley_exit(
        anchor_span_m, horizontal_tension_n, vertical_tension_n, cable, radius, epsilon
    )
    compliance = extensions.axial_compliance_per_n
    unstretched, drop, t_top = elastic_free_length(
        span, horizontal_tension_n, vertical_tension_n, cable, compliance, epsilon
    )
    chain_length, chain_drop = segmented_chain(
        span, horizontal_tension_n, vertical_tension_n, cable, extensions.inverse_segments_squared, epsilon
    )
    paid_out = unstretched + chain_length + radius * wrap / (1 + compliance * t_top)
    return paid_out, drop + chain_drop - rise


def safe_divisor(x: sf.Scalar, epsilon: sf.Scalar) -> sf.Scalar:
    """Return ``x`` pushed away from zero by ``epsilon``, keeping its sign.

    ``x + sign_no_zero(x) * epsilon`` is branchless (``signum`` in Rust, with
    ``sign_no_zero(0) = +1``), never zero, and equal to ``x`` up to
    ``epsilon``. Its derivative is exactly that of ``x``.

    Args:
        x: The divisor.
        epsilon: Small positive number.

    Returns:
        A divisor that is never zero.
    """
    return x + sf.sign_no_zero(x) * epsilon


def sinhc(y: sf.Scalar, epsilon: sf.Scalar) -> sf.Scalar:
    """``sinh(y) / y``, finite and accurate for every ``y``, including ``y = 0`` exactly.

    Used by the stable catenary formulas (paper eq. 1 and 4, see
    :func:`catenary_length`). The division is made safe without a branch:
    ``y_s = y + sign_no_zero(y) * epsilon`` (:func:`safe_divisor`) and
    ``sinhc(y) = sinh(y_s) / y_s``. For ``y = 0`` (a massless cable,
    ``g_c = 0``) this is ``sinh(epsilon) / epsilon``, which is exactly 1.0 in
    floating point for any ``epsilon < 1e-8``. For ``y != 0`` the shift changes
    the value by ``sinhc'(y) * epsilon ~ y * epsilon / 3``, far below an ulp.
    ``sinh`` of a small argument is accurate to an ulp (libm), so no digits are
    lost in the value. The derivative ``(y cosh y - sinh y) / y^2`` loses
    digits for tiny ``y``, but every ``dy/d(argument)`` of the catenary is
    proportional to ``y`` (``y = g_c L / (2 f_h)``), so the absolute error of
    the chained Jacobian stays at machine precision.

    Args:
        y: The argument (``lambda / 2`` of the catenary).
        epsilon: Small positive number.

    Returns:
        ``sinh(y) / y`` (1 at ``y = 0``).
    """
    # Branchless safe division: y_s = y + signum(y) * epsilon is never 0 (signum(0) = +1), and at
    # y = 0 (g_c = 0) sinh(epsilon) / epsilon == 1.0 exactly, so the massless cable is the straight one.
    y_safe = safe_divisor(y, epsilon)
    return sf.sinh(y_safe) / y_safe


def horizontal_span(anchor: sf.V3, attachment_world: sf.V3, epsilon: sf.Scalar) -> tuple[sf.Scalar, sf.V3]:
    """Span and horizontal direction of a cable's vertical plane (paper Sec. III-A).

    ``L = ||b_xy - a_xy||`` (the ``L_i`` of eq. 2) and
    ``s_c = (b_xy - a_xy) / L`` (the unit vector ``s_c`` of Sec. III-A, eq. 8),
    with the norm made safe by ``epsilon`` (``sqrt(dx^2 + dy^2 + epsilon)``).

    Args:
        anchor: Anchor (pulley exit) ``p_a``, world frame, metres.
        attachment_world: Attachment point ``p + R p_b``, world frame, metres.
        epsilon: Small positive number.

    Returns:
        ``(L, s)``: the span in metres and the horizontal unit 3-vector (z = 0)
        from the anchor towards the attachment.
    """
    delta = attachment_world - anchor
    span = checkpoint(sf.sqrt(delta[0] ** 2 + delta[1] ** 2 + epsilon))
    direction = checkpoint(sf.V3(delta[0] / span, delta[1] / span, 0))
    return span, direction


def catenary_length(
    span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    epsilon: sf.Scalar,
) -> sf.Scalar:
    """Arc length of the catenary from the anchor to the attachment (paper eq. 4), stable form.

    Eq. (4) is ``l_C = f_h/g_c (sinh(g_c/f_h (L + C1)) - sinh(g_c/f_h C1))``
    with ``C1`` from eq. (2). With ``u = f_v/f_h``, ``lambda = g_c L / f_h``,
    ``A = asinh(u)`` (so ``g_c C1 / f_h = -(A + lambda)``) and
    ``sinh(p) - sinh(q) = 2 cosh((p+q)/2) sinh((p-q)/2)`` it becomes the
    difference-free product of ``src/model/catenary.rs``::

        l_C = L * sinhc(lambda/2) * cosh(A + lambda/2)

    which tends to the straight cable ``L sqrt(1 + u^2)`` as ``g_c -> 0`` and
    equals it at ``g_c = 0`` (see :func:`sinhc`).

    Args:
        span_m: Horizontal span ``L``, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment (upward pull on the platform > 0), newtons.
        cable: The cable's properties (``g_c``).
        epsilon: Small positive number.

    Returns:
        The cable length ``l_C`` in metres.
    """
    u = vertical_tension_n / horizontal_tension_n
    half_lambda = cable.weight_n_per_m * span_m / (2 * horizontal_tension_n)
    return span_m * sinhc(half_lambda, epsilon) * sf.cosh(sf.asinh(u) + half_lambda)


def catenary_drop(
    span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable: CableProperties,
    epsilon: sf.Scalar,
) -> sf.Scalar:
    """Height of the anchor above the attachment, ``a_z - z(L)`` (paper eq. 1-3 at ``x = L``), stable form.

    Eq. (1) with the constants of eq. (2)-(3) gives
    ``z(L) - a_z = f_h/g_c (cosh(g_c/f_h (L + C1)) - cosh(g_c/f_h C1))``; with
    the substitutions of :func:`catenary_length` and
    ``cosh(p) - cosh(q) = 2 sinh((p+q)/2) sinh((p-q)/2)``::

        a_z - z(L) = L * sinhc(lambda/2) * sinh(A + lambda/2)

    (``L u`` for the massless cable).

    Args:
        span_m: Horizontal span ``L``, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment (upward pull on the platform > 0), newtons.
        cable: The cable's properties (``g_c``).
        epsilon: Small positive number.

    Returns:
        The drop ``a_z - z(L)`` in metres.
    """
    u = vertical_tension_n / horizontal_tension_n
    half_lambda = cable.weight_n_per_m * span_m / (2 * horizontal_tension_n)
    return span_m * sinhc(half_lambda, epsilon) * sf.sinh(sf.asinh(u) + half_lambda)


def attachments_world(position_m: sf.V3, rotation: sf.Rot3, attachments_m: sf.Matrix34) -> list[sf.V3]:
    """Attachment points in the world frame, ``p + R b_j`` (paper Sec. III-A), in slot order.

    Args:
        position_m: Platform origin ``p``, world frame, metres.
        rotation: Platform orientation ``R``.
        attachments_m: Column ``j`` = attachment ``b_j`` of slot ``j``, platform frame, metres.

    Returns:
        The four world-frame attachment points.
    """
    matrix = rotation_matrix(rotation)
    return [checkpoint(position_m + matrix * attachments_m[:, j]) for j in range(CABLE_COUNT)]


def platform_wrench(rotation: sf.Rot3, com_offset_m: sf.V3, platform_weight_n: sf.Scalar) -> sf.Matrix:
    """The wrench the cables must supply, paper eq. (6): ``w = [z; (R b_com) x z] m_e g``.

    The force, and the moment about the platform origin ``p``, in world axes.

    Args:
        rotation: Platform orientation ``R``.
        com_offset_m: Centre of mass ``b_com``, platform frame, metres.
        platform_weight_n: ``m_e g``, newtons.

    Returns:
        The 6-vector ``[force; moment]``.
    """
    moment_arm = checkpoint(rotation_matrix(rotation) * com_offset_m)
    return sf.Matrix.block_matrix([[UP], [moment_arm.cross(UP)]]) * platform_weight_n


def solve3(matrix: sf.Matrix33, rhs: sf.V3, epsilon: sf.Scalar) -> sf.V3:
    """Solve a 3x3 linear system by Cramer's rule with a safe determinant.

    ``x = adj(A) b / det(A)``, with ``det`` pushed away from zero by
    :func:`safe_divisor`. Only used for the small blocks of eq. (11). Its
    Jacobians are implicit (``dx = A^-1 (db - dA x)``,
    ``forward_mode.linear_solution``), not the quotient rule of Cramer's formulas.

    Args:
        matrix: ``A``.
        rhs: ``b``.
        epsilon: Small positive number.

    Returns:
        ``x`` with ``A x = b``.
    """
    c0, c1, c2 = matrix[:, 0], matrix[:, 1], matrix[:, 2]
    det = checkpoint(safe_divisor(c0.dot(c1.cross(c2)), epsilon))
    # Cramer: x_k = det(A with column k replaced by b) / det(A) = (row k of adj(A)) . b / det(A),
    # the rows of the adjugate being c1 x c2, c2 x c0 and c0 x c1.
    inverse = sf.Matrix33.block_matrix([[c1.cross(c2).T], [c2.cross(c0).T], [c0.cross(c1).T]]) / det
    return linear_solution(inverse, matrix, rhs)


def cable_tensions_from_reference(
    position_m: sf.V3,
    rotation: sf.Rot3,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> list[tuple[sf.Scalar, sf.Scalar]]:
    """Tensions of all cables from the reference cable's, paper eq. (5)-(11), without a 6x6 inverse.

    Eq. (8): the column pair of cable ``j`` in ``J^T`` is
    ``[[-s_j, z], [-r_j x s_j, r_j x z]]`` with ``r_j = R b_j`` and ``s_j`` its
    horizontal unit vector (z component 0). Eq. (5) ``J^T f = w`` with eq. (6)
    ``w = W [z; c x z]`` (``c = R b_com``, ``W = m_e g``), written per row::

        Fx:  sum_j -s_jx f_hj                              = 0
        Fy:  sum_j -s_jy f_hj                              = 0
        Mz:  sum_j -(r_jx s_jy - r_jy s_jx) f_hj           = 0        ((r x z)_z = 0, (c x z)_z = 0)
        Fz:  sum_j f_vj                                    = W
        Mx:  sum_j ( r_jz s_jy f_hj + r_jy f_vj)           = W c_y    ((r x s)_x = -r_z s_y, (r x z)_x = r_y)
        My:  sum_j (-r_jz s_jx f_hj - r_jx f_vj)           = -W c_x   ((r x s)_y = r_z s_x, (r x z)_y = -r_x)

    (``s_jz = 0`` was used). The rows ``[Fx, Fy, Mz]`` contain only the
    horizontal tensions, so eq. (11), ``f_res = (J_res^T)^-1 (w - J_ref^T f_ref)``,
    is block triangular: after moving the reference cable's (slot 0) terms to
    the right-hand side,

    1. ``[Fx, Fy, Mz]`` is a 3x3 system in ``f_h1..f_h3`` (columns
       ``[-s_jx, -s_jy, -(r_j x s_j)_z]``);
    2. with those known, ``[Fz, Mx, My]`` is a 3x3 system in ``f_v1..f_v3``
       (columns ``[1, r_jy, -r_jx]``).

    Both are solved with :func:`solve3`. This is exactly eq. (11) when
    ``J_res^T`` is invertible (its determinant is the product of the two 3x3
    determinants) and keeps the generated expressions small.

    Args:
        position_m: Platform origin ``p``, world frame, metres.
        rotation: Platform orientation ``R``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass ``b_com``, platform frame, metres.
        platform_weight_n: ``m_e g``, newtons.
        epsilon: Small positive number.

    Returns:
        ``[(f_h0, f_v0), ..., (f_h3, f_v3)]`` in slot order; slot 0 is the input.
    """
    matrix = rotation_matrix(rotation)
    arms = [checkpoint(matrix * attachments_m[:, j]) for j in range(CABLE_COUNT)]
    directions = []
    for j in range(CABLE_COUNT):
        _, direction = horizontal_span(anchors_m[:, j], position_m + arms[j], epsilon)
        directions.append(direction)
    wrench = platform_wrench(rotation, com_offset_m, platform_weight_n)

    def horizontal_column(j: int) -> sf.V3:
        # Rows [Fx, Fy, Mz] of the f_h column of eq. (8).
        r, s = arms[j], directions[j]
        return sf.V3(-s[0], -s[1], -(r[0] * s[1] - r[1] * s[0]))

    def vertical_column(j: int) -> sf.V3:
        # Rows [Fz, Mx, My] of the f_v column of eq. (8).
        r = arms[j]
        return sf.V3(1, r[1], -r[0])

    def horizontal_in_vertical_rows(j: int) -> sf.V3:
        # Rows [Fz, Mx, My] of the f_h column of eq. (8).
        r, s = arms[j], directions[j]
        return sf.V3(0, r[2] * s[1], -r[2] * s[0])

    f_h_ref, f_v_ref = reference_tension_n[0], reference_tension_n[1]
    others = range(1, CABLE_COUNT)

    # Step 1: rows [Fx, Fy, Mz] (wrench rows 0, 1, 5), unknowns f_h of slots 1..3.
    rhs_h = sf.V3(wrench[0], wrench[1], wrench[5]) - horizontal_column(REFERENCE_SLOT) * f_h_ref
    a_h = sf.Matrix33.column_stack(*[horizontal_column(j) for j in others])
    f_h = solve3(a_h, rhs_h, epsilon)

    # Step 2: rows [Fz, Mx, My] (wrench rows 2, 3, 4), unknowns f_v of slots 1..3.
    rhs_v = sf.V3(wrench[2], wrench[3], wrench[4]) - horizontal_in_vertical_rows(REFERENCE_SLOT) * f_h_ref
    rhs_v = rhs_v - vertical_column(REFERENCE_SLOT) * f_v_ref
    for k, j in enumerate(others):
        rhs_v = rhs_v - horizontal_in_vertical_rows(j) * f_h[k]
    a_v = sf.Matrix33.column_stack(*[vertical_column(j) for j in others])
    f_v = solve3(a_v, rhs_v, epsilon)

    return [(f_h_ref, f_v_ref)] + [(f_h[k], f_v[k]) for k in range(CABLE_COUNT - 1)]


def straight_cable_length(anchor: sf.V3, attachment_world: sf.V3, epsilon: sf.Scalar) -> sf.Scalar:
    """Length of a massless (straight) cable, ``||a - (p + R b)||`` (the ``g_c = 0`` limit of eq. 4).

    Args:
        anchor: Anchor ``p_a``, world frame, metres.
        attachment_world: Attachment point ``p + R p_b``, world frame, metres.
        epsilon: Small positive number (inside the square root).

    Returns:
        The distance in metres.
    """
    return (anchor - attachment_world).norm(epsilon=epsilon)
