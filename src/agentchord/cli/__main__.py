"""``python -m agentchord.cli``: the ``agentchord`` command."""

from agentchord.cli.app import main

if __name__ == "__main__":  # pragma: no cover
    main()
