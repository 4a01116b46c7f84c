"""Data for policy learning: LeRobot v3.0 datasets of AgentChord episodes, Rerun recordings."""
