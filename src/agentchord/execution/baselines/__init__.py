"""The four baselines of the paper's comparison, on the same executor as AgentChord.

They differ from AgentChord only in how a failure is detected and what happens then
(DESIGN section 6; docs/results.md, "The methods", says how each follows its paper):

- ``inner-monologue``: a VQA success query when each sub-goal's edge ends; on a "no", re-plan.
- ``doremi``: a VQA query on the step's constraints every k ticks of motion and at each
  sub-goal; on a violation, halt and re-plan.
- ``rekep``: the stage's path constraints every tick; on a violation, backtrack to the latest
  earlier stage whose path constraints hold (or that has none) and run on from there.
- ``code-as-monitor``: the compiled monitors every tick and the sub-goal's constraints at its
  end; on a detection, re-plan; the reasoner is called again at every sub-goal.

Re-planning is the project's own composer, arranger and conductor from the current
observation (:class:`~agentchord.agents.pipeline.Replanner`).
"""

from agentchord.execution.baselines.strategies import (
    BASELINES,
    CodeAsMonitorStrategy,
    DoReMiStrategy,
    InnerMonologueStrategy,
    ReKepStrategy,
)

__all__ = ["BASELINES", "CodeAsMonitorStrategy", "DoReMiStrategy", "InnerMonologueStrategy", "ReKepStrategy"]
