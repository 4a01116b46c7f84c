"""Policy learning on AgentChord datasets: the small CPU policy and the Table III experiment."""
