"""``OracleSynthesis``: the forms a phase oracle diag((-1)^marks) is built in, the one table of them.

- ``DIAGONAL`` (``"diagonal"``): one diagonal gate of 2^n phases;
- ``MCZ`` (``"mcz"``): one multi-controlled Z (or phase) per marked index, conjugated by X on its
  zero bits;
- ``AUTO`` (``"auto"``): the builder picks one of the two for the marks (``circuits.choose_synthesis``
  by CX count for hardware, ``aer_circuits.simulation_synthesis`` by simulation speed for Aer).

Constructors and builders take the strings or the members (``OracleSynthesis.parse``); a member is
a ``str`` equal to its value, so it prints, compares and serializes as the string it stands for.
"""

from __future__ import annotations

import enum

__all__ = ["OracleSynthesis"]


class OracleSynthesis(enum.StrEnum):
    """The form of a phase oracle: ``"auto"``, ``"diagonal"`` or ``"mcz"`` (module docstring).

    Example:
        >>> from qrrt_circuits.search.synthesis import OracleSynthesis
        >>> OracleSynthesis.parse("mcz") is OracleSynthesis.MCZ, OracleSynthesis.MCZ == "mcz"
        (True, True)
    """

    AUTO = "auto"
    DIAGONAL = "diagonal"
    MCZ = "mcz"

    @classmethod
    def parse(cls, value: object, name: str = "synthesis") -> OracleSynthesis:
        """The member ``value`` names: a member, or its string.

        Args:
            value: ``"auto"``, ``"diagonal"``, ``"mcz"`` or a member.
            name: The argument's name, for the error.

        Returns:
            The member.

        Raises:
            ValueError: Any other value.
        """
        if isinstance(value, str):
            try:
                return cls(value)
            except ValueError:
                pass
        raise ValueError(f"{name} must be one of {tuple(member.value for member in cls)}, got {value!r}")
