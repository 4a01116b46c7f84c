"""Compiled monitors, the persistence trigger (Eq. 12) and the recovery map (Eq. 13)."""

from agentchord.monitor.compiled import CompiledMonitor, Detection, EdgeMonitors
from agentchord.monitor.recovery_map import RecoveryMap
from agentchord.monitor.trigger import PersistenceTrigger

__all__ = ["CompiledMonitor", "Detection", "EdgeMonitors", "PersistenceTrigger", "RecoveryMap"]
