"""The offline ``rules`` reasoner: goal predicates, a STRIPS planner over skills, arranger rules, a conductor."""

from agentchord.agents.rules.goals import Folded, GoalSpec, HandedOver, Inside, On, Placed, Poured
from agentchord.agents.rules.reasoner import RulesReasoner

__all__ = ["Folded", "GoalSpec", "HandedOver", "Inside", "On", "Placed", "Poured", "RulesReasoner"]
