"""The residuals of sagcal's factor graph (paper Sec. IV-C, eq. 14-16), built from ``cable_model``.

Each function is pure symbolic: it takes the generated function's arguments
(same names, same order) and returns the residual as a column matrix.
``generate.py`` differentiates it (pose Jacobians on SymForce's ``Rot3``
tangent, i.e. the right perturbation ``R * Exp(dtheta)`` of
``src/model/pose.rs``) and emits Rust.

Argument conventions:

* ``position_m`` (V3): platform origin ``p`` in the world frame;
  ``rotation_xyzw`` (V4): its orientation as a quaternion in SymForce storage
  order ``[x, y, z, w]``, turned into an ``sf.Rot3`` here.
* Cable slots: slot 0 is the reference cable (the one with the load cell),
  slots 1..3 the others; the Rust caller permutes the robot's cables.
  ``anchors_m`` / ``attachments_m`` (3x4): column ``j`` belongs to slot ``j``
  (world frame / platform frame). ``length_offsets_m``, ``encoder_lengths_m``
  (V4) are in slot order too.
* ``reference_tension_n`` (V2): ``[f_h, f_v]`` of the reference cable at its
  attachment (``f_v > 0``: the cable pulls the platform up).
* Residuals are not whitened; noise models live in Rust.
"""

from __future__ import annotations

import symforce

# generate.py calls this first; every function here takes `epsilon` explicitly anyway.
try:
    symforce.set_epsilon_to_symbol()
except symforce.AlreadyUsedEpsilon:
    pass

import symforce.symbolic as sf  # noqa: E402  (must follow set_epsilon_to_symbol)

import cable_model  # noqa: E402
from cable_model import CABLE_COUNT  # noqa: E402


def rotation_from_storage(rotation_xyzw: sf.V4) -> sf.Rot3:
    """The ``sf.Rot3`` whose storage (``[x, y, z, w]``) is the given 4-vector.

    Args:
        rotation_xyzw: Unit quaternion, SymForce storage order.

    Returns:
        The rotation.
    """
    return sf.Rot3.from_storage(list(rotation_xyzw))


def cable_tensions_from_reference(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """Horizontal and vertical tensions of all four cables from the reference cable's (eq. 5-11).

    Eq. (11) solved through its block-triangular structure, see
    ``cable_model.cable_tensions_from_reference``.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass, platform frame, metres.
        platform_weight_n: Platform weight ``m_e g``, newtons.
        epsilon: Small positive number (safe divisions).

    Returns:
        ``[f_h0, f_v0, f_h1, f_v1, f_h2, f_v2, f_h3, f_v3]`` in newtons, slot order
        (slot 0 = ``reference_tension_n``).
    """
    tensions = cable_model.cable_tensions_from_reference(
        position_m,
        rotation_from_storage(rotation_xyzw),
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    return sf.Matrix([component for pair in tensions for component in pair])


def _catenaries(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> tuple[list[sf.V3], list[sf.Scalar], list[tuple[sf.Scalar, sf.Scalar]]]:
    """World attachment points, spans and tensions of the four cables (eq. 2, 5-11)."""
    rotation = rotation_from_storage(rotation_xyzw)
    attachments = cable_model.attachments_world(position_m, rotation, attachments_m)
    spans = [cable_model.horizontal_span(anchors_m[:, j], attachments[j], epsilon)[0] for j in range(CABLE_COUNT)]
    tensions = cable_model.cable_tensions_from_reference(
        position_m,
        rotation,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    return attachments, spans, tensions


def _length_rows(
    spans: list[sf.Scalar],
    tensions: list[tuple[sf.Scalar, sf.Scalar]],
    cable_weight_n_per_m: sf.Scalar,
    length_offsets_m: sf.V4,
    encoder_lengths_m: sf.V4,
    epsilon: sf.Scalar,
) -> list[sf.Scalar]:
    """Eq. (14) per slot: ``l_C,j + l0_j - z_enc,j``."""
    cable = cable_model.CableProperties(weight_n_per_m=cable_weight_n_per_m)
    return [
        cable_model.catenary_length(spans[j], tensions[j][0], tensions[j][1], cable, epsilon)
        + length_offsets_m[j]
        - encoder_lengths_m[j]
        for j in range(CABLE_COUNT)
    ]


def _height_rows(
    attachments: list[sf.V3],
    spans: list[sf.Scalar],
    tensions: list[tuple[sf.Scalar, sf.Scalar]],
    anchors_m: sf.Matrix34,
    cable_weight_n_per_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> list[sf.Scalar]:
    """Eq. (15) per slot: ``(p + R b_j)_z - a_j,z + drop_j``."""
    cable = cable_model.CableProperties(weight_n_per_m=cable_weight_n_per_m)
    return [
        attachments[j][2]
        - anchors_m[2, j]
        + cable_model.catenary_drop(spans[j], tensions[j][0], tensions[j][1], cable, epsilon)
        for j in range(CABLE_COUNT)
    ]


def catenary_length_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    cable_weight_n_per_m: sf.Scalar,
    length_offsets_m: sf.V4,
    encoder_lengths_m: sf.V4,
    epsilon: sf.Scalar,
) -> sf.V4:
    """Catenary length factor, paper eq. (14): ``r_j = l_C,j + l0_j - z_enc,j``.

    ``l_C,j`` is the catenary length of eq. (4) (stable form,
    ``cable_model.catenary_length``) with the span of slot ``j`` and the
    tensions of eq. (11) (``cable_model.cable_tensions_from_reference``).

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass, platform frame, metres.
        platform_weight_n: Platform weight ``m_e g``, newtons.
        cable_weight_n_per_m: Cable weight per metre ``g_c``, N/m (0: massless cable).
        length_offsets_m: Encoder length offsets ``l0_j``, metres, slot order.
        encoder_lengths_m: Encoder readings ``z_enc,j``, metres, slot order.
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        The 4-vector of length errors in metres, slot order.
    """
    _, spans, tensions = _catenaries(
        position_m,
        rotation_xyzw,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    return sf.V4(_length_rows(spans, tensions, cable_weight_n_per_m, length_offsets_m, encoder_lengths_m, epsilon))


def attachment_height_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    cable_weight_n_per_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.V4:
    """Cable attachment factor, paper eq. (15): ``r_j = (p + R b_j)_z - z_j(L_j)``.

    ``z_j(L_j) = a_j,z - drop_j`` from eq. (1)-(3) (stable form,
    ``cable_model.catenary_drop``), so ``r_j = (p + R b_j)_z - a_j,z + drop_j``.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass, platform frame, metres.
        platform_weight_n: Platform weight ``m_e g``, newtons.
        cable_weight_n_per_m: Cable weight per metre ``g_c``, N/m (0: massless cable).
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        The 4-vector of height errors in metres, slot order.
    """
    attachments, spans, tensions = _catenaries(
        position_m,
        rotation_xyzw,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    return sf.V4(_height_rows(attachments, spans, tensions, anchors_m, cable_weight_n_per_m, epsilon))


def catenary_cable_residuals(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    cable_weight_n_per_m: sf.Scalar,
    length_offsets_m: sf.V4,
    encoder_lengths_m: sf.V4,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """Both catenary factors of one pose, eq. (14) and (15), and its tensions, from one statics solve.

    The rows are exactly ``catenary_length_residual`` (0..4),
    ``attachment_height_residual`` (4..8) and
    ``cable_tensions_from_reference`` (8..16, read by the tension guard); the
    attachment points, spans and the tensions of eq. (11) they share are
    derived once, so one call costs little more than one of the three did.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass, platform frame, metres.
        platform_weight_n: Platform weight ``m_e g``, newtons.
        cable_weight_n_per_m: Cable weight per metre ``g_c``, N/m (0: massless cable).
        length_offsets_m: Encoder length offsets ``l0_j``, metres, slot order.
        encoder_lengths_m: Encoder readings ``z_enc,j``, metres, slot order.
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        The 16-vector: the length errors (eq. 14, metres), the height errors
        (eq. 15, metres), each in slot order, then
        ``[f_h0, f_v0, ..., f_h3, f_v3]`` (eq. 11, newtons, slot order).
    """
    attachments, spans, tensions = _catenaries(
        position_m,
        rotation_xyzw,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    lengths = _length_rows(spans, tensions, cable_weight_n_per_m, length_offsets_m, encoder_lengths_m, epsilon)
    heights = _height_rows(attachments, spans, tensions, anchors_m, cable_weight_n_per_m, epsilon)
    return sf.Matrix(lengths + heights + [component for pair in tensions for component in pair])


def reference_tension_residual(
    reference_tension_n: sf.V2,
    measured_tension_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.V1:
    """Force measurement factor, paper eq. (16): ``r = ||[f_h, f_v]|| - f_m``.

    Args:
        reference_tension_n: ``[f_h, f_v]`` of the reference cable, newtons.
        measured_tension_n: Load-cell reading ``f_m``, newtons.
        epsilon: Small positive number (inside the norm's square root).

    Returns:
        The 1-vector tension error in newtons.
    """
    return sf.V1(reference_tension_n.norm(epsilon=epsilon) - measured_tension_n)


def rotation_log(rotation: sf.Rot3, epsilon: sf.Scalar) -> sf.V3:
    """Logarithm of a rotation, ``Log(R)`` (rotation vector, angle <= pi), accurate near the identity.

    Same value as SymForce's ``Rot3.to_tangent`` and nalgebra's
    ``scaled_axis`` (``PlatformPose::local_coordinates``), computed without
    cancellation. With the quaternion ``(v, w)`` flipped to ``w >= 0`` and
    ``n = |v|``, the angle is ``2 atan2(n, w) = 4 atan(n / (1 + w))`` (the
    half-angle identity, valid for unit quaternions), so::

        Log = v * 4 atan(n / (1 + w)) / n,   n = sqrt(v.v + epsilon)

    ``1 + w >= 1`` and ``n > 0`` keep the value and every derivative free of
    singularities (also at 180 degrees, unlike the derivative of ``atan2``),
    and ``atan(t) / n`` is well conditioned for every ``n``; ``epsilon``
    changes the result by about ``epsilon / 12`` relative. SymForce's
    ``Rot3.to_tangent`` divides ``acos(w)`` by ``sqrt(1 - w^2)``, which loses
    about ``1e-16 / angle^2`` relative accuracy (5e-11 at 1 mrad).

    Args:
        rotation: A unit-quaternion rotation.
        epsilon: Small positive number.

    Returns:
        The rotation vector, radians.
    """
    q = rotation.q
    # The same rotation with w >= 0; sign_no_zero has a zero derivative.
    sign = sf.sign_no_zero(q.w)
    n = sf.sqrt(q.xyz.squared_norm() + epsilon)
    return q.xyz * (sign * 4 * sf.atan(n / (1 + q.w * sign)) / n)


def pose_prior_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    prior_position_m: sf.V3,
    prior_rotation_xyzw: sf.V4,
    epsilon: sf.Scalar,
) -> sf.V6:
    """Pose prior factor (paper Sec. IV-C.4): ``[Log(R_prior^-1 R); p - p_prior]``.

    The rotation part is the logarithm of :func:`rotation_log` (the value of
    SymForce's ``Rot3.to_tangent``, more accurate near the identity), so the
    residual is ``PlatformPose::local_coordinates`` of ``src/model/pose.rs``
    from the prior to the pose, the inverse of its retraction.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        prior_position_m: Measured (prior) platform origin, metres.
        prior_rotation_xyzw: Measured (prior) orientation, quaternion ``[x, y, z, w]``.
        epsilon: Small positive number (the logarithm near the identity).

    Returns:
        The 6-vector ``[rotation error (rad, 3); position error (m, 3)]``.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    prior_rotation = rotation_from_storage(prior_rotation_xyzw)
    rotation_error = rotation_log(prior_rotation.inverse() * rotation, epsilon)
    return sf.V6(list(rotation_error) + list(position_m - prior_position_m))


def mounted_pose_prior_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    prior_position_m: sf.V3,
    prior_rotation_xyzw: sf.V4,
    localiser_mount_rad: sf.V3,
    epsilon: sf.Scalar,
) -> sf.V6:
    """Pose prior factor of a localiser mounted with a rotation ``M = Exp(m)``: ``[Log(M R_prior^-1 R); p - p_prior]``.

    A localiser fixed to the platform with its axes turned by ``M`` (platform
    frame) reports the orientation of its own body, ``R_prior = R M``, so the
    platform orientation it implies is ``R_prior M^-1`` and the rotation error
    is ``Log((R_prior M^-1)^-1 R) = Log(M R_prior^-1 R)`` (:func:`rotation_log`).
    With ``m = 0`` this is :func:`pose_prior_residual`. The mount is one
    rotation shared by every pose (3 parameters, a structured localiser fault),
    where freeing every orientation costs 3 per pose. The position rows are
    unchanged (the localiser's origin is taken at the platform origin).

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        prior_position_m: Measured (prior) platform origin, metres.
        prior_rotation_xyzw: Measured (prior) orientation, quaternion ``[x, y, z, w]``.
        localiser_mount_rad: The mounting rotation ``m`` as a rotation vector, platform frame, radians.
        epsilon: Small positive number (the logarithm and exponential near the identity).

    Returns:
        The 6-vector ``[rotation error (rad, 3); position error (m, 3)]``.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    prior_rotation = rotation_from_storage(prior_rotation_xyzw)
    mount = sf.Rot3.from_tangent(localiser_mount_rad, epsilon=epsilon)
    rotation_error = rotation_log(mount * prior_rotation.inverse() * rotation, epsilon)
    return sf.V6(list(rotation_error) + list(position_m - prior_position_m))


def rigid_length_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    length_offsets_m: sf.V4,
    encoder_lengths_m: sf.V4,
    epsilon: sf.Scalar,
) -> sf.V4:
    """Massless-cable length factor: ``r_j = ||a_j - (p + R b_j)|| + l0_j - z_enc,j``.

    The straight-cable model of the authors' earlier work (paper Sec. VI-A),
    the ``g_c -> 0`` limit of eq. (14).

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        length_offsets_m: Encoder length offsets ``l0_j``, metres, slot order.
        encoder_lengths_m: Encoder readings ``z_enc,j``, metres, slot order.
        epsilon: Small positive number (inside the norm's square root).

    Returns:
        The 4-vector of length errors in metres, slot order.
    """
    attachments = cable_model.attachments_world(position_m, rotation_from_storage(rotation_xyzw), attachments_m)
    return sf.V4(
        [
            cable_model.straight_cable_length(anchors_m[:, j], attachments[j], epsilon)
            + length_offsets_m[j]
            - encoder_lengths_m[j]
            for j in range(CABLE_COUNT)
        ]
    )



def cable_geometry(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    reference_tension_n: sf.V2,
    anchors_m: sf.Matrix34,
    attachments_m: sf.Matrix34,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """Per cable, what its catenary depends on: span, end tensions and the anchor's height (eq. 2, 5-11).

    The extended model's factors (``src/calib/effect_factors.rs``) chain these
    through :func:`extended_cable`, so the effects' terms are derived once per
    cable instead of once per pose.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        reference_tension_n: ``[f_h, f_v]`` of the reference cable (slot 0), newtons.
        anchors_m: Column ``j`` = anchor of slot ``j``, world frame, metres.
        attachments_m: Column ``j`` = attachment of slot ``j``, platform frame, metres.
        com_offset_m: Centre of mass, platform frame, metres.
        platform_weight_n: Platform weight ``m_e g``, newtons.
        epsilon: Small positive number (safe divisions).

    Returns:
        ``[L_0, f_h0, f_v0, h_0, L_1, ...]`` (16): per slot the horizontal span
        ``L`` (m), the tensions at the attachment (N) and the anchor's height
        above the attachment ``h = a_z - (p + R b)_z`` (m).
    """
    attachments, spans, tensions = _catenaries(
        position_m,
        rotation_xyzw,
        reference_tension_n,
        anchors_m,
        attachments_m,
        com_offset_m,
        platform_weight_n,
        epsilon,
    )
    values = []
    for j in range(CABLE_COUNT):
        values += [spans[j], tensions[j][0], tensions[j][1], anchors_m[2, j] - attachments[j][2]]
    return sf.Matrix(values)


def extended_cable(
    span_m: sf.Scalar,
    horizontal_tension_n: sf.Scalar,
    vertical_tension_n: sf.Scalar,
    cable_weight_n_per_m: sf.Scalar,
    axial_compliance_per_mn: sf.Scalar,
    pulley_radius_m: sf.Scalar,
    inverse_segments_squared: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.V2:
    """Paid-out length and implied drop of one cable with pulley wrap, elasticity and finite elements.

    ``cable_model.extended_cable``: Irvine's elastic catenary to first order in
    ``1/EA`` from the swivelling pulley's exit point, plus the arc wrapped on
    the pulley, and the length and drop of a chain of ``n`` straight elements
    to first order in ``1/n^2``. The extended length factor is ``(1 + g_j) paid_out_j + l0_j -
    z_enc,j`` (eq. 14 with an encoder scale error ``g_j``), the extended
    attachment factor ``drop_j - h_j`` (eq. 15, ``h_j`` from
    :func:`cable_geometry`). With the three effect parameters 0 the outputs
    are exactly eq. (4) and the drop of eq. (1)-(3).

    Args:
        span_m: Horizontal span ``L`` from the anchor to the attachment, metres.
        horizontal_tension_n: ``f_h > 0``, newtons.
        vertical_tension_n: ``f_v`` at the attachment, newtons.
        cable_weight_n_per_m: Cable weight per metre ``g_c``, N/m (0: massless cable).
        axial_compliance_per_mn: ``1e6 / EA`` of the cable, 1/MN (0: inextensible).
        pulley_radius_m: Pulley radius ``r``, metres (0: point anchor).
        inverse_segments_squared: ``1/n^2`` for a cable of ``n`` straight elements (0: smooth).
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        ``[paid_out, drop]``: the length paid out past the anchor and the
        anchor's height above the attachment the cable implies, metres.
    """
    cable = cable_model.CableProperties(weight_n_per_m=cable_weight_n_per_m)
    extensions = cable_model.CableExtensions(
        axial_compliance_per_n=axial_compliance_per_mn * sf.Rational(1, 10**6),
        pulley_radius_m=pulley_radius_m,
        inverse_segments_squared=inverse_segments_squared,
    )
    paid_out, drop = cable_model.extended_cable(
        span_m, horizontal_tension_n, vertical_tension_n, cable, extensions, epsilon
    )
    return sf.V2(paid_out, drop)

def load_cell_residual(
    reference_tension_n: sf.V2,
    load_cell_bias_n: sf.Scalar,
    load_cell_gain_error: sf.Scalar,
    measured_tension_n: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.V1:
    """Force factor with a load-cell model: ``r = b + (1 + g) ||[f_h, f_v]|| - f_m`` (eq. 16 extended).

    A load cell with zero-point error ``b`` and sensitivity error ``g`` reads
    ``b + (1 + g) T``; with ``b = g = 0`` this is :func:`reference_tension_residual`.

    Args:
        reference_tension_n: ``[f_h, f_v]`` of the reference cable, newtons.
        load_cell_bias_n: Zero-point error ``b``, newtons.
        load_cell_gain_error: Sensitivity error ``g`` (dimensionless).
        measured_tension_n: Load-cell reading ``f_m``, newtons.
        epsilon: Small positive number (inside the norm's square root).

    Returns:
        The 1-vector tension error in newtons.
    """
    tension = reference_tension_n.norm(epsilon=epsilon)
    return sf.V1(load_cell_bias_n + (1 + load_cell_gain_error) * tension - measured_tension_n)


def suspended_cable_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    cable_tension_n: sf.V2,
    anchor_m: sf.V3,
    attachment_m: sf.V3,
    cable_weight_n_per_m: sf.Scalar,
    length_offset_m: sf.Scalar,
    encoder_length_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """One cable of a robot of any number of cables, its forces its own: eq. (14) and (15).

    The rows are ``l_C + l0 - z_enc`` (eq. 14) and ``(p + R b)_z - a_z +
    drop`` (eq. 15) of one cable, with ``(f_h, f_v)`` given rather than
    solved from a reference cable (a robot of ``N`` cables carries its
    forces as variables, balanced by :func:`cable_wrench`).

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        cable_tension_n: ``[f_h, f_v]`` of this cable at its attachment, newtons.
        anchor_m: The cable's anchor, world frame, metres.
        attachment_m: The cable's attachment, platform frame, metres.
        cable_weight_n_per_m: The cable's weight per metre ``g_c``, N/m (0: massless).
        length_offset_m: The encoder's length offset ``l0``, metres.
        encoder_length_m: The encoder's reading ``z_enc``, metres.
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        ``[length error (m), height error (m)]``.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    attachment = position_m + rotation * attachment_m
    span, _ = cable_model.horizontal_span(anchor_m, attachment, epsilon)
    cable = cable_model.CableProperties(weight_n_per_m=cable_weight_n_per_m)
    f_h, f_v = cable_tension_n[0], cable_tension_n[1]
    length = cable_model.catenary_length(span, f_h, f_v, cable, epsilon) + length_offset_m - encoder_length_m
    height = attachment[2] - anchor_m[2] + cable_model.catenary_drop(span, f_h, f_v, cable, epsilon)
    return sf.Matrix([length, height])


def suspended_elastic_cable_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    cable_tension_n: sf.V2,
    anchor_m: sf.V3,
    attachment_m: sf.V3,
    cable_weight_n_per_m: sf.Scalar,
    axial_compliance_per_mn: sf.Scalar,
    length_offset_m: sf.Scalar,
    encoder_length_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """One elastic cable of a robot of any number of cables: eq. (14) and (15) with Irvine's stretch.

    :func:`suspended_cable_residual` for a cable of axial stiffness ``EA``:
    the drum pays out the unstretched length ``L0 = l (1 - T_top / EA)``
    and the attachment hangs ``g_c l^2 / (2 EA)`` lower
    (``cable_model.elastic_free_length``, Irvine's elastic catenary to first
    order in ``1/EA``). The length row ``L0 + l0 - z_enc`` depends on the
    cable's tension, which the inextensible rows leave to the weight's sag
    alone: stiffness is what fixes the forces of a light cable. With the
    compliance 0 the rows are :func:`suspended_cable_residual`'s, and they
    are ``cable_model.extended_cable``'s with no pulley and a smooth cable.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        cable_tension_n: ``[f_h, f_v]`` of this cable at its attachment, newtons.
        anchor_m: The cable's anchor, world frame, metres.
        attachment_m: The cable's attachment, platform frame, metres.
        cable_weight_n_per_m: The cable's weight per metre ``g_c``, N/m (0: massless).
        axial_compliance_per_mn: ``1e6 / EA`` of the cable, 1/MN (0: inextensible).
        length_offset_m: The encoder's length offset ``l0``, metres.
        encoder_length_m: The encoder's reading ``z_enc``, metres.
        epsilon: Small positive number (safe divisions, ``sinhc`` at ``g_c = 0``).

    Returns:
        ``[length error (m), height error (m)]``.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    attachment = position_m + rotation * attachment_m
    span, _ = cable_model.horizontal_span(anchor_m, attachment, epsilon)
    cable = cable_model.CableProperties(weight_n_per_m=cable_weight_n_per_m)
    f_h, f_v = cable_tension_n[0], cable_tension_n[1]
    compliance = axial_compliance_per_mn * sf.Rational(1, 10**6)
    unstretched, drop, _ = cable_model.elastic_free_length(span, f_h, f_v, cable, compliance, epsilon)
    length = unstretched + length_offset_m - encoder_length_m
    height = attachment[2] - anchor_m[2] + drop
    return sf.Matrix([length, height])


def cable_wrench(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    cable_tension_n: sf.V2,
    anchor_m: sf.V3,
    attachment_m: sf.V3,
    epsilon: sf.Scalar,
) -> sf.Matrix:
    """The wrench one cable puts on the platform about its origin (paper eq. 5-8, one column pair).

    The cable pulls its attachment ``r = R b`` with ``F = -s f_h + z f_v``
    (``s`` the horizontal unit vector from the anchor towards the
    attachment, ``cable_model.horizontal_span``); the platform is in
    equilibrium where the cables' wrenches and gravity's
    (``cable_model.platform_wrench``) sum to zero.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        cable_tension_n: ``[f_h, f_v]`` of this cable at its attachment, newtons.
        anchor_m: The cable's anchor, world frame, metres.
        attachment_m: The cable's attachment, platform frame, metres.
        epsilon: Small positive number (safe divisions).

    Returns:
        ``[F (3), r x F (3)]``, newtons and newton-metres, world axes.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    lever = rotation * attachment_m
    _, direction = cable_model.horizontal_span(anchor_m, position_m + lever, epsilon)
    force = -direction * cable_tension_n[0] + sf.V3(0, 0, 1) * cable_tension_n[1]
    moment = lever.cross(force)
    return sf.Matrix([force[0], force[1], force[2], moment[0], moment[1], moment[2]])


def platform_weight_wrench(
    rotation_xyzw: sf.V4,
    com_offset_m: sf.V3,
    platform_weight_n: sf.Scalar,
) -> sf.Matrix:
    """The wrench the cables must supply to hold the platform, paper eq. (6), about its origin.

    ``w = [z; (R b_com) x z] m_e g`` (``cable_model.platform_wrench``): a
    robot of ``N`` cables is in equilibrium where the sum of its cables'
    :func:`cable_wrench` equals it. The position does not enter (the
    moment is about the platform origin), so the Jacobian is the
    orientation's alone: the first three columns of a pose block.

    Args:
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        com_offset_m: Centre of mass ``b_com``, platform frame, metres.
        platform_weight_n: ``m_e g``, newtons.

    Returns:
        ``[force (3), moment (3)]``, newtons and newton-metres, world axes.
    """
    rotation = rotation_from_storage(rotation_xyzw)
    return cable_model.platform_wrench(rotation, com_offset_m, platform_weight_n)


def straight_cable_residual(
    position_m: sf.V3,
    rotation_xyzw: sf.V4,
    anchor_m: sf.V3,
    attachment_m: sf.V3,
    length_offset_m: sf.Scalar,
    encoder_length_m: sf.Scalar,
    epsilon: sf.Scalar,
) -> sf.V1:
    """One massless cable's length factor: ``||a - (p + R b)|| + l0 - z_enc``.

    :func:`rigid_length_residual` for one cable of a robot of any number of
    cables: the straight-cable stage that brings a calibration of ``N``
    cables from a rough guess to where the catenary graph starts.

    Args:
        position_m: Platform origin, world frame, metres.
        rotation_xyzw: Platform orientation, quaternion ``[x, y, z, w]``.
        anchor_m: The cable's anchor, world frame, metres.
        attachment_m: The cable's attachment, platform frame, metres.
        length_offset_m: The encoder's length offset ``l0``, metres.
        encoder_length_m: The encoder's reading ``z_enc``, metres.
        epsilon: Small positive number (inside the norm's square root).

    Returns:
        The 1-vector length error in metres.
    """
    attachment = position_m + rotation_from_storage(rotation_xyzw) * attachment_m
    length = cable_model.straight_cable_length(anchor_m, attachment, epsilon)
    return sf.V1(length + length_offset_m - encoder_length_m)
