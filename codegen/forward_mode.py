"""Jacobians by the chain rule through named intermediate quantities (forward mode, symbolic).

Differentiating a whole residual at once (``sf.Matrix.jacobian``) expands the
chain rule into every entry: the quotient rule of the Cramer solves of eq. (11)
is applied to the full expressions, then again inside the catenary, and common
subexpression elimination cannot fold the products back. The generated
Jacobians then cost about 11 times the value.

Here the model marks its intermediate quantities with :func:`checkpoint`
(attachment points and arms, spans and horizontal directions, the solutions of
eq. 11; marking the catenary's ``u`` and ``lambda`` too was tried and made
the code longer). While a :class:`Tape` records, each marked quantity is
replaced by a fresh symbol and its defining expression is kept. The Jacobian of
an output with respect to a block of inputs is then the chain rule, applied
quantity by quantity (forward-mode automatic differentiation with symbolic
local partials)::

    d q / d x = sum over the quantities u that q is written in: (partial q / partial u) (d u / d x)

where ``d u / d x`` is the seed of the block (identity for an additive
argument) or the row of an earlier quantity. Two quantities have their own,
cheaper rule instead of the partials of their expression:

* :func:`rotation_matrix`: along the right perturbation ``R Exp(dtheta)`` of the
  pose, ``d R / d dtheta_k = R [e_k]x`` (Sola et al., *A micro Lie theory for
  state estimation in robotics*, 2018, eq. 146: ``d(R v)/d theta = -R [v]x``).
  Its entries are entries of ``R`` up to sign, so the rotation costs nothing.
* :func:`linear_solution`: ``x = A^-1 b`` is differentiated implicitly,
  ``dx = A^-1 (db - dA x)`` (differentiate ``A x = b``), which reuses the
  inverse instead of applying the quotient rule to Cramer's formulas.

Finally every marked symbol is replaced by its expression; the common
subexpression elimination of the code generator recovers the shared
quantities. The values are the same expressions as without a tape; the
Jacobians are the same functions, computed in fewer operations.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence

import symforce.symbolic as sf
from symforce.ops import LieGroupOps

# A Jacobian row: the derivative of one quantity along each tangent direction of a block.
Row = list[sf.Expr]
# Gives the row of any expression (in the inputs and the recorded quantities).
RowOf = Callable[[sf.Expr], Row]

# The tape that the functions below record on; None: they return plain expressions.
_ACTIVE_TAPE: Tape | None = None


class Tape:
    """The recorded quantities: their symbols, expressions and derivative rules."""

    def __init__(self) -> None:
        # symbol -> its expression in the inputs and earlier symbols, in recording order.
        self.definitions: dict[sf.Symbol, sf.Expr] = {}
        # symbol -> its own derivative rule (see linear_solution), instead of its expression's partials.
        self.rules: dict[sf.Symbol, Callable[[RowOf, int], Row]] = {}
        # Per rotation (its storage symbols), the symbols of its rotation matrix.
        self.rotation_matrices: dict[tuple[sf.Expr, ...], sf.Matrix33] = {}

    def record(self, expr: sf.Expr) -> sf.Expr:
        """A fresh symbol standing for ``expr`` (symbols and numbers are returned as they are)."""
        expr = sf.S(expr)
        if expr.is_Symbol or expr.is_Number:
            return expr
        symbol = sf.Symbol(f"checkpoint{len(self.definitions)}")
        self.definitions[symbol] = expr
        return symbol

    def expand(self, matrix: sf.Matrix) -> sf.Matrix:
        """``matrix`` with every recorded symbol replaced by its expression in the inputs."""
        expanded: dict[sf.Symbol, sf.Expr] = {}
        for symbol, expr in self.definitions.items():
            expanded[symbol] = expr.subs(expanded)
        return matrix.applyfunc(lambda entry: sf.S(entry).subs(expanded))

    def pose_seeds(self, rotation_xyzw: sf.V4, position_m: sf.V3 | None) -> dict[sf.Symbol, Row]:
        """Seeds of the pose block, tangent ``[dtheta (3), dp (3)]`` of ``(R Exp(dtheta), p + dp)``.

        Without a position (``None``), the seeds of the orientation alone,
        tangent ``dtheta (3)`` of ``R Exp(dtheta)``.

        The quaternion's storage gets SymForce's ``storage_D_tangent`` (the
        ``Rot3`` tangent of ``sf.Matrix.jacobian``); the rotation matrices
        recorded from it get ``R [e_k]x`` directly (their expressions in the
        quaternion are then never differentiated).
        """
        storage = list(rotation_xyzw)
        storage_d_tangent = LieGroupOps.storage_D_tangent(sf.Rot3.from_storage(storage))
        zero3 = [sf.S(0)] * (3 if position_m is not None else 0)
        seeds: dict[sf.Symbol, Row] = {}
        for i, symbol in enumerate(storage):
            seeds[symbol] = [storage_d_tangent[i, k] for k in range(3)] + zero3
        for i, symbol in enumerate(position_m if position_m is not None else []):
            seeds[symbol] = zero3 + [sf.S(1 if k == i else 0) for k in range(3)]
        matrix = self.rotation_matrices.get(tuple(storage))
        if matrix is not None:
            # Column k of the derivative of R along dtheta_k: R [e_k]x.
            units = (sf.V3.unit_x(), sf.V3.unit_y(), sf.V3.unit_z())
            derivatives = [matrix * sf.Matrix33.skew_symmetric(unit) for unit in units]
            for i in range(3):
                for j in range(3):
                    seeds[matrix[i, j]] = [derivatives[k][i, j] for k in range(3)] + zero3
        return seeds

    def jacobian(self, outputs: Sequence[sf.Expr], seeds: dict[sf.Symbol, Row], columns: int) -> sf.Matrix:
        """``d outputs / d x`` for the block ``x`` whose symbols have the given seeds.

        Args:
            outputs: Expressions in the inputs and the recorded symbols.
            seeds: Per symbol of the block, its derivative along each of the block's
                ``columns`` tangent directions. A seeded recorded symbol keeps its
                seed (its expression is not differentiated).
            columns: Tangent dimension of the block.

        Returns:
            The ``len(outputs) x columns`` Jacobian, still in the recorded symbols
            (:meth:`expand` them).
        """
        zero = [sf.S(0)] * columns
        rows: dict[sf.Symbol, Row] = {symbol: [sf.S(x) for x in seed] for symbol, seed in seeds.items()}

        def row_of_symbol(symbol: sf.Symbol) -> Row:
            if symbol not in rows:
                if symbol in self.rules:
                    rows[symbol] = self.rules[symbol](row_of, columns)
                elif symbol in self.definitions:
                    rows[symbol] = row_of(self.definitions[symbol])
                else:
                    rows[symbol] = zero  # an input outside the block
            return rows[symbol]

        def row_of(expr: sf.Expr) -> Row:
            expr = sf.S(expr)
            row = list(zero)
            # Sorted by name: the same sums built in the same order on every run.
            for symbol in sorted(expr.free_symbols, key=str):
                inner = row_of_symbol(symbol)
                if all(entry == 0 for entry in inner):
                    continue
                partial = expr.diff(symbol)
                if partial == 0:
                    continue
                for k, entry in enumerate(inner):
                    if entry != 0:
                        row[k] += partial * entry
            return row

        return sf.Matrix([row_of(output) for output in outputs])


def checkpoint(value):  # type: ignore[no-untyped-def]
    """Mark a scalar or a matrix (entry by entry) as an intermediate quantity of the chain rule.

    Without an active :func:`recording` the value is returned unchanged, so the
    model functions stay plain symbolic functions.
    """
    if _ACTIVE_TAPE is None:
        return value
    if isinstance(value, sf.Matrix):
        return value.applyfunc(_ACTIVE_TAPE.record)
    return _ACTIVE_TAPE.record(value)


def rotation_matrix(rotation: sf.Rot3) -> sf.Matrix33:
    """``rotation``'s matrix; on a tape, symbols whose pose derivative is ``R [e_k]x`` (:meth:`Tape.pose_seeds`)."""
    matrix = rotation.to_rotation_matrix()
    if _ACTIVE_TAPE is None:
        return matrix
    key = tuple(rotation.to_storage())
    if key not in _ACTIVE_TAPE.rotation_matrices:
        _ACTIVE_TAPE.rotation_matrices[key] = checkpoint(matrix)
    return _ACTIVE_TAPE.rotation_matrices[key]


def linear_solution(inverse: sf.Matrix33, matrix: sf.Matrix33, rhs: sf.V3) -> sf.V3:
    """``x = inverse * rhs`` where ``inverse = matrix^-1``, differentiated as ``dx = inverse (d rhs - d matrix x)``.

    The rule is the derivative of ``matrix x = rhs``; it holds to the accuracy of
    ``inverse`` (a safe determinant changes it by ``epsilon / det``).
    """
    solution = inverse * rhs
    if _ACTIVE_TAPE is None:
        return solution
    tape = _ACTIVE_TAPE
    inverse = checkpoint(inverse)
    matrix = checkpoint(matrix)
    rhs = checkpoint(rhs)
    symbols = checkpoint(inverse * rhs)

    def rule(k: int) -> Callable[[RowOf, int], Row]:
        def derivative(row_of: RowOf, columns: int) -> Row:
            rhs_rows = [row_of(rhs[m]) for m in range(3)]
            matrix_rows = [[row_of(matrix[m, n]) for n in range(3)] for m in range(3)]
            row = []
            for c in range(columns):
                # (d rhs - d matrix x) along tangent direction c, then row k of the inverse.
                residual = [rhs_rows[m][c] - sum(matrix_rows[m][n][c] * symbols[n] for n in range(3)) for m in range(3)]
                row.append(sum(inverse[k, m] * residual[m] for m in range(3)))
            return row

        return derivative

    for k in range(3):
        tape.rules[symbols[k]] = rule(k)
    return symbols


@contextlib.contextmanager
def recording() -> Iterator[Tape]:
    """Record the quantities that the model functions mark inside the ``with`` block."""
    global _ACTIVE_TAPE
    previous, _ACTIVE_TAPE = _ACTIVE_TAPE, Tape()
    try:
        yield _ACTIVE_TAPE
    finally:
        _ACTIVE_TAPE = previous
