"""The ``agentchord`` command line.

Exit statuses (:mod:`agentchord.cli.support`): 0 success, 1 the task failed (``run``),
2 bad input (usage errors, unreadable or invalid files, unwritable output paths),
3 internal error (one line, the traceback in a log file it names).

Modules: ``app`` the ``agentchord`` group and ``tasks``, ``serve``, ``plan``; ``episode`` ``run`` and
``demo``; ``graph`` ``schema``, ``graph ...``, ``import-release``; ``bench``; ``data`` ``record``;
``support`` exit statuses, the error handler and what the commands share.
"""

from agentchord.cli.app import main

__all__ = ["main"]
