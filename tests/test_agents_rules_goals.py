

def test_a_kind_yaml_read_as_a_boolean_is_named_with_the_kinds():
    """A newcomer's `kind: on` (YAML reads a bare `on` as true) failed with "Input tag 'True' found using 'kind'"."""
    import pytest
    from pydantic import ValidationError

    from agentchord.agents.rules.goals import GoalSpec

    with pytest.raises(ValidationError, match=r"goals\[0\]\.kind: YAML read it as true .* on_top_of"):
        GoalSpec.model_validate({"goals": [{"kind": True, "obj": "red_block", "support": "blue_block"}]})
