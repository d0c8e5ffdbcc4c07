"""How a simulation ended: an enum of actionable messages (after diffrax's RESULTS)."""
from __future__ import annotations

import enum


class ActionableOutcome(enum.Enum):
    """An enum of how something ended, whose values are actionable messages; its first member is
    the one success (``ok``).  The base of camdyn's outcome enums."""

    @property
    def ok(self) -> bool:
        return self is next(iter(type(self)))

    @property
    def message(self) -> str:
        return self.value


class Outcome(ActionableOutcome):
    SUCCESS = "the run reached t_end"
    STEP_FAILED = ("the Runge-Kutta method could not take a step (step size underflow); tighten or "
                   "loosen rtol/atol; a very stiff contact (large Y_c, Y_b) may need max_step")
    MAX_EVENTS = ("more regime switches than EventSettings.max_events; the run may be chattering "
                  "(Zeno-like impacts or Coulomb stick): raise max_events or use friction='tanh'")
    CHATTER = ("a switching surface was crossed back and forth with no progress in time "
               "(Coulomb stick or grazing); use friction='tanh' or a stick-slip treatment")
    NONFINITE = "the state became NaN or infinite; check the rig parameters and tolerances"
    ANGLE_LIMIT = ("the follower angle approached 90 degrees, where tan(alpha) and sec(alpha) of "
                   "Eq. 11 blow up; the follower has left the cam for good")
    #: the scene option response="quasistatic" (camdyn.runs.quasistatic), never the engine's loop (whose
    #: codes index camdyn.engine.loop.OUTCOMES, the members above): the samples stop before it
    CONTACT_TENSILE = ("the quasi-static contact force F_n would turn tensile (<= 0): the follower leaves the "
                       "cam there (result.stats['where'] says when and at which cam angle) and the quasi-static "
                       "orbit does not exist; use the full model (response='dynamic')")
    NO_QUASI_STATIC = ("no contact deformation carries the follower's inertia (Newton's method did not converge; "
                       "result.stats['where'] says when): use the full model (response='dynamic')")
    #: the engine loop's too (camdyn.engine.loop.OUTCOMES), last so that the codes of the members above (a
    #: sweep's outcome variable) stay what they were
    OFF_FACE = ("the contact reached an end of the follower's bounded face (where the rig says it starts or "
                "ends), or an impact would land beyond one: the cam would touch the face's edge, which the model does "
                "not describe; lengthen the face (or move it), or run at another speed")
