"""A user force that raises inside a run: the suites' case of a user function failing after the start."""


def raise_after_one_second(t, r, v):
    """A spring of unit stiffness that raises ``ValueError("too late")`` once t passes 1 s."""
    if t > 1.0:
        raise ValueError("too late")
    return -r[0], -r[1], -r[2]
