"""AgentChord: proactive failure recovery through recovery-augmented task graphs."""

__version__ = "0.1.0"
