"""Tests of the LLM reasoner against a local OpenAI-compatible replay server (127.0.0.1 only)."""

from __future__ import annotations

import json
import re
import socket

import openai
import pytest
from replay_server import Completion, HttpError, ReplayServer

from agentchord.actions.catalog import ACTIONS
from agentchord.agents import (
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    InvalidReplyError,
    Reasoner,
    ReasonerConfigError,
    ReasonerTransportError,
    Scene,
    SceneObject,
    UnanticipatedFailure,
)
from agentchord.agents.llm import (
    ENV_API_KEY,
    ENV_BASE_URL,
    ENV_MODEL,
    LlmConfig,
    LlmReasoner,
    backoff_delay,
    extract_json,
    parse_reply,
    system_prompt,
    task_graph_schema,
)
from agentchord.agents.prompts import EXAMPLE_GOAL, nominal_part, prompt_names, render_prompt
from agentchord.expr import FUNCTIONS, TEMPLATES
from agentchord.graph.models import ActionCall, Success, TaskGraph
from agentchord.library import load_task_graph

BASE = 0.01  # back-off base in tests: fast


@pytest.fixture(scope="module")
def augmented() -> TaskGraph:
    # The composer states its goal; the arranger and the conductor keep it.
    return load_task_graph("single_arm_pour_water").model_copy(update={"success": Success(judge="goal", goal_spec=EXAMPLE_GOAL)})


@pytest.fixture(scope="module")
def nominal(augmented: TaskGraph) -> TaskGraph:
    return nominal_part(augmented)


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene(
        objects=[
            SceneObject(name="bottle", pos=(0.10, 0.42, 0.09), extent=(0.05, 0.05, 0.18)),
            SceneObject(name="cup", pos=(0.0, 0.50, 0.05), extent=(0.08, 0.08, 0.10)),
        ]
    )


@pytest.fixture
def server():
    with ReplayServer() as replay:
        yield replay


class Sleeps(list):
    """Records back-off delays instead of sleeping."""

    def __call__(self, seconds: float) -> None:
        self.append(seconds)


def reasoner(server: ReplayServer, sleep=None, **settings) -> LlmReasoner:
    settings.setdefault("backoff_base_s", BASE)
    settings.setdefault("timeout_s", 10.0)
    config = LlmConfig(base_url=server.base_url, model="replay-model", api_key="test-key", **settings)
    return LlmReasoner(config, sleep=sleep) if sleep is not None else LlmReasoner(config)


def reply(graph: TaskGraph, **kwargs) -> Completion:
    return Completion(json.dumps(graph.model_dump(mode="json", exclude_defaults=True)), **kwargs)


def compose_request(nominal: TaskGraph, scene: Scene) -> ComposeRequest:
    return ComposeRequest(instruction=nominal.instruction, scene=scene, task=nominal.task)


# --- configuration -----------------------------------------------------------------------


def test_config_names_every_missing_variable():
    with pytest.raises(ReasonerConfigError) as caught:
        LlmConfig.from_env({})
    assert caught.value.missing == [ENV_BASE_URL, ENV_MODEL, ENV_API_KEY]
    assert f"{ENV_BASE_URL}, {ENV_MODEL}, {ENV_API_KEY} are not set" in str(caught.value)
    with pytest.raises(ReasonerConfigError, match=f"{ENV_MODEL} is not set") as caught:
        LlmConfig.from_env({ENV_BASE_URL: "http://127.0.0.1:1/v1", ENV_API_KEY: "none"})
    assert caught.value.missing == [ENV_MODEL]


def test_config_from_environment_and_overrides():
    env = {
        ENV_BASE_URL: "http://127.0.0.1:1/v1",
        ENV_MODEL: "env-model",
        ENV_API_KEY: "secret",
        "AGENTCHORD_LLM_STRUCTURED_OUTPUT": "text",
        "AGENTCHORD_LLM_TIMEOUT_S": "7.5",
        "AGENTCHORD_LLM_MAX_TOKENS": "4000",
    }
    config = LlmConfig.from_env(env, model="flag-model", temperature=None)
    assert (config.model, config.structured_output, config.timeout_s, config.max_tokens) == (
        "flag-model", "text", 7.5, 4000
    )
    assert config.temperature is None
    assert "secret" not in repr(config) and "secret" not in json.dumps(config.settings())
    with pytest.raises(ReasonerConfigError, match="AGENTCHORD_LLM_TIMEOUT_S='soon': expected a number"):
        LlmConfig.from_env({**env, "AGENTCHORD_LLM_TIMEOUT_S": "soon"})
    with pytest.raises(ReasonerConfigError, match="structured_output: expected one of auto, json_schema"):
        LlmConfig.from_env({**env, "AGENTCHORD_LLM_STRUCTURED_OUTPUT": "xml"})
    with pytest.raises(TypeError, match="no field modle"):
        LlmConfig.from_env(env, modle="x")


def test_reasoner_without_configuration_fails_clearly(monkeypatch):
    for var in (ENV_BASE_URL, ENV_MODEL, ENV_API_KEY):
        monkeypatch.delenv(var, raising=False)
    with pytest.raises(ReasonerConfigError, match=ENV_API_KEY):
        LlmReasoner()


def test_backoff_doubles_up_to_the_cap():
    assert [backoff_delay(n, 0.5, 3.0) for n in range(5)] == [0.5, 1.0, 2.0, 3.0, 3.0]


# --- prompts and schema ------------------------------------------------------------------


def test_every_agent_has_a_prompt_with_generated_tables():
    assert prompt_names() == ["arranger", "composer", "conductor"]
    for agent in prompt_names():
        text = render_prompt(agent)
        assert re.search(r"\{\{\s*\w+\s*\}\}", text) is None, agent  # every placeholder filled
        for name in ACTIONS:
            assert f"`{name}`" in text, (agent, name)
        for name in FUNCTIONS:
            if agent != "composer" or name not in TEMPLATES:
                assert f"`{name}(" in text, (agent, name)
        for info in TEMPLATES.values():
            assert (info.signature in text) == (agent != "composer")  # the composer writes no monitors
    assert '"goal_spec"' in render_prompt("composer")  # the example states its goal
    assert "r_bottle_regrasped" not in render_prompt("composer")  # the nominal example only
    assert "r_bottle_regrasped" in render_prompt("arranger")
    with pytest.raises(KeyError, match="no prompt for agent 'planner'"):
        render_prompt("planner")


def test_schema_is_self_contained_and_follows_the_model():
    schema = task_graph_schema()
    assert "$ref" not in json.dumps(schema) and "$defs" not in schema
    assert set(schema["properties"]) == set(TaskGraph.model_fields)
    assert set(schema["required"]) == {"task", "start", "goal", "nodes", "edges"}
    assert "JSON Schema" in system_prompt("composer", "text")
    assert "JSON Schema" not in system_prompt("composer", "json_schema")


def test_extract_json_reads_what_models_write():
    assert extract_json('{"a": 1}') == {"a": 1}
    assert extract_json('Here it is:\n```json\n{"a": 1}\n```\nDone.') == {"a": 1}
    assert extract_json('<think>plan {x}</think>\nSure: {"a": [1, 2]} hope this helps') == {"a": [1, 2]}
    with pytest.raises(ValueError, match="line 1, column 9: Expecting value"):
        extract_json('{"task": ')


def test_parse_reply_fills_what_the_request_determines(nominal, scene):
    data = nominal.model_dump(mode="json", exclude_defaults=True)
    del data["instruction"], data["objects"]
    graph, problems = parse_reply(json.dumps(data), compose_request(nominal, scene))
    assert problems == [] and graph == nominal
    assert parse_reply("[1, 2]", compose_request(nominal, scene)) == (
        None, ["expected one JSON object (the task graph), got a JSON array"]
    )


# --- one call against the replay server ---------------------------------------------------


def test_valid_reply_gives_a_task_graph_and_records_the_call(server, nominal, scene):
    server.push(reply(nominal, prompt_tokens=3000, completion_tokens=700, delay_s=0.05))
    llm = reasoner(server)
    assert isinstance(llm, Reasoner)
    graph = llm.compose(compose_request(nominal, scene))
    assert graph == nominal

    (body,) = server.bodies()
    assert server.requests[0].headers["authorization"] == "Bearer test-key"
    assert body["model"] == "replay-model"
    assert [m["role"] for m in body["messages"]] == ["system", "user"]
    assert "task structuring agent" in body["messages"][0]["content"]
    assert nominal.instruction in body["messages"][1]["content"]
    assert '"name": "bottle"' in body["messages"][1]["content"]
    assert body["response_format"]["type"] == "json_schema"
    assert body["response_format"]["json_schema"]["name"] == "task_graph"
    assert body["response_format"]["json_schema"]["schema"] == task_graph_schema()

    (call,) = llm.calls
    assert (call.agent, call.reasoner, call.model) == ("composer", "llm", "replay-model")
    assert call.endpoint == server.base_url
    assert call.ok and call.repairs == 0 and call.errors == []
    assert (call.tokens_in, call.tokens_out) == (3000, 700)
    assert call.latency_s >= 0.05 and call.attempts[0].latency_s >= 0.05
    assert call.attempts[0].response_format == "json_schema"
    assert call.request["instruction"] == nominal.instruction
    assert TaskGraph.model_validate(call.reply) == nominal
    assert [m["role"] for m in call.messages] == ["system", "user", "assistant"]
    assert json.loads(call.messages[-1]["content"]) == nominal.model_dump(mode="json", exclude_defaults=True)
    assert call.settings["max_repairs"] == 3 and "api_key" not in call.settings
    json.dumps(call.to_trace_event())  # serialisable as is


def test_invalid_replies_are_repaired_with_their_problems(server, nominal, scene):
    schema_error = nominal.model_dump(mode="json", exclude_defaults=True)
    del schema_error["nodes"]
    unknown_node = nominal.model_copy(deep=True)
    unknown_node.edges[0].target = "v9"
    server.push(
        Completion('{"task": "single_arm_pour_water", "nodes": [ oops'),
        Completion(json.dumps(schema_error)),
        reply(unknown_node),
        reply(nominal),
    )
    llm = reasoner(server)
    assert llm.compose(compose_request(nominal, scene)) == nominal

    bodies = server.bodies()
    assert len(bodies) == 4
    repairs = [body["messages"][-1] for body in bodies[1:]]
    assert all(m["role"] == "user" and m["content"].startswith("Your reply is not a valid task graph") for m in repairs)
    assert "the reply is not valid JSON: line 1, column 46: Expecting value" in repairs[0]["content"]
    assert "- nodes: Field required" in repairs[1]["content"]
    assert "- edges[0].target: unknown node 'v9'" in repairs[2]["content"]
    # The conversation keeps each rejected reply before its repair request.
    assert bodies[3]["messages"][-2] == {"role": "assistant", "content": json.dumps(unknown_node.model_dump(
        mode="json", exclude_defaults=True))}
    assert len(bodies[3]["messages"]) == 2 + 2 * 3

    (call,) = llm.calls
    assert call.ok and call.repairs == 3 and len(call.attempts) == 4
    assert [bool(a.problems) for a in call.attempts] == [True, True, True, False]
    assert (call.tokens_in, call.tokens_out) == (4 * 120, 4 * 80)


def test_unrepairable_reply_raises_after_three_repairs(server, nominal, scene):
    bad = nominal.model_copy(deep=True)
    bad.edges[0].actions = [{"right": ActionCall(fn="teleport")}]
    server.push(*[reply(bad) for _ in range(5)])
    llm = reasoner(server)
    with pytest.raises(InvalidReplyError) as caught:
        llm.compose(compose_request(nominal, scene))
    error = caught.value
    assert len(server.bodies()) == 4 and len(server.queue) == 1
    assert "composer: no valid task graph from replay-model after 3 repairs" in str(error)
    assert any("edges[0].actions.right.fn: unknown action 'teleport'" in p for p in error.problems)
    assert "unknown action 'teleport'" in str(error)
    assert error.agent == "composer" and error.call is llm.calls[-1]
    assert not error.call.ok and error.call.error.startswith("composer: no valid task graph")
    assert error.call.repairs == 3


def test_max_repairs_is_a_setting(server, nominal, scene):
    server.push(Completion("nope"), Completion("still nope"), reply(nominal))
    with pytest.raises(InvalidReplyError, match="after 1 repair;"):
        reasoner(server, max_repairs=1).compose(compose_request(nominal, scene))
    assert len(server.bodies()) == 2


def test_server_errors_and_rate_limits_are_retried_with_backoff(server, nominal, scene):
    server.push(HttpError(500, "overloaded"), HttpError(429, "slow down"), HttpError(502), reply(nominal))
    sleeps = Sleeps()
    llm = reasoner(server, sleep=sleeps)
    assert llm.compose(compose_request(nominal, scene)) == nominal
    assert sleeps == [BASE, 2 * BASE, 4 * BASE]
    assert len(server.bodies()) == 4
    (attempt,) = llm.calls[0].attempts
    assert attempt.retries == 3
    assert attempt.transport_errors[0] == "HTTP 500: overloaded; retry 1/4 in 0.01 s"
    assert attempt.transport_errors[1].startswith("HTTP 429: slow down; retry 2/4")
    assert llm.calls[0].ok


def test_backoff_really_waits(server, nominal, scene):
    server.push(HttpError(503), HttpError(503), reply(nominal))
    llm = reasoner(server, backoff_base_s=0.05)
    llm.compose(compose_request(nominal, scene))
    first, second, third = (r.at for r in server.requests)
    assert second - first >= 0.05 and third - second >= 0.1
    assert llm.calls[0].latency_s >= 0.15


def test_retry_after_header_is_honoured(server, nominal, scene):
    server.push(HttpError(429, headers={"retry-after": "0.25"}), reply(nominal))
    sleeps = Sleeps()
    reasoner(server, sleep=sleeps).compose(compose_request(nominal, scene))
    assert sleeps == [0.25]


def test_transport_gives_up_after_max_retries(server, nominal, scene):
    server.push(*[HttpError(503, "down") for _ in range(4)])
    sleeps = Sleeps()
    llm = reasoner(server, sleep=sleeps, max_retries=2)
    with pytest.raises(ReasonerTransportError, match="answered HTTP 503 after 3 tries") as caught:
        llm.compose(compose_request(nominal, scene))
    assert caught.value.status == 503 and len(server.bodies()) == 3 and sleeps == [BASE, 2 * BASE]
    assert llm.calls[0].error and not llm.calls[0].ok


def test_client_errors_are_not_retried(server, nominal, scene):
    server.push(HttpError(401, "bad key"), reply(nominal))
    with pytest.raises(ReasonerTransportError, match=f"HTTP 401 \\(check {ENV_API_KEY}\\)") as caught:
        reasoner(server, sleep=Sleeps()).compose(compose_request(nominal, scene))
    assert caught.value.status == 401 and "bad key" in str(caught.value)
    assert len(server.bodies()) == 1


def test_connection_errors_are_retried(nominal, scene):
    with socket.socket() as probe:  # a port that nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    config = LlmConfig(base_url=f"http://127.0.0.1:{port}/v1", model="m", api_key="k", max_retries=2)
    sleeps = Sleeps()
    llm = LlmReasoner(config, sleep=sleeps)
    with pytest.raises(ReasonerTransportError, match="no reply from .* after 3 tries") as caught:
        llm.compose(compose_request(nominal, scene))
    assert caught.value.status is None and len(sleeps) == 2
    assert all("connection error" in line for line in llm.calls[0].attempts[0].transport_errors)


def test_timeouts_are_retried(server, nominal, scene):
    server.push(reply(nominal, delay_s=1.0), reply(nominal))
    llm = reasoner(server, timeout_s=0.3, sleep=Sleeps())
    assert llm.compose(compose_request(nominal, scene)) == nominal
    assert llm.calls[0].attempts[0].transport_errors[0].startswith("timed out after 0.3 s; retry 1/4")


# --- structured-output modes ---------------------------------------------------------------


def test_auto_mode_falls_back_when_json_schema_is_refused_and_keeps_what_worked(server, nominal, scene):
    server.push(HttpError(400, "response_format json_schema is not supported"), reply(nominal), reply(nominal))
    llm = reasoner(server, structured_output="auto")
    llm.compose(compose_request(nominal, scene))
    first, second = server.bodies()
    assert first["response_format"]["type"] == "json_schema"
    assert second["response_format"] == {"type": "json_object"}
    assert "JSON Schema" in second["messages"][0]["content"]
    assert llm.calls[0].attempts[0].response_format == "json_object"
    assert "falling back to 'json_object'" in llm.calls[0].attempts[0].transport_errors[0]

    llm.compose(compose_request(nominal, scene))
    assert server.bodies()[2]["response_format"] == {"type": "json_object"}
    # Once a mode has answered, a 400 is an error, not a reason to fall back.
    server.push(HttpError(400, "context too long"))
    with pytest.raises(ReasonerTransportError, match="HTTP 400"):
        llm.compose(compose_request(nominal, scene))


def test_fixed_json_schema_mode_does_not_fall_back(server, nominal, scene):
    server.push(HttpError(400, "unsupported"), reply(nominal))
    with pytest.raises(ReasonerTransportError, match="HTTP 400"):
        reasoner(server, structured_output="json_schema").compose(compose_request(nominal, scene))
    assert len(server.bodies()) == 1


def test_text_mode_reads_json_from_prose(server, nominal, scene):
    text = json.dumps(nominal.model_dump(mode="json", exclude_defaults=True), indent=2)
    server.push(Completion(f"Here is the graph:\n```json\n{text}\n```"))
    assert reasoner(server, structured_output="text").compose(compose_request(nominal, scene)) == nominal
    (body,) = server.bodies()
    assert "response_format" not in body
    assert "JSON Schema" in body["messages"][0]["content"]


def test_sampling_settings_are_sent(server, nominal, scene):
    server.push(reply(nominal))
    reasoner(server, temperature=0.2, max_tokens=8000, seed=7, extra_body={"top_k": 20}).compose(
        compose_request(nominal, scene)
    )
    (body,) = server.bodies()
    assert (body["temperature"], body["max_tokens"], body["seed"], body["top_k"]) == (0.2, 8000, 7, 20)


def test_missing_usage_refusals_and_truncation(server, nominal, scene):
    server.push(
        Completion(None, refusal="I cannot help with robots."),
        Completion('{"task": "t", "nodes": [', finish_reason="length", usage=False),
        reply(nominal, usage=False),
    )
    llm = reasoner(server)
    llm.compose(compose_request(nominal, scene))
    call = llm.calls[0]
    assert call.attempts[0].problems == ["the model refused: I cannot help with robots."]
    assert "cut off at the token limit" in call.attempts[1].problems[0]
    assert call.attempts[1].tokens_in is None and call.tokens_in == 120


# --- the other agents ----------------------------------------------------------------------


def test_arrange_gets_the_nominal_graph_and_repairs_a_changed_nominal_edge(server, nominal, augmented, scene):
    changed = augmented.model_copy(deep=True)
    changed.edges[4].actions = [{"right": ActionCall(fn="place", args={"obj": "bottle"})}]
    server.push(reply(changed), reply(augmented))
    llm = reasoner(server)
    assert llm.arrange(ArrangeRequest(graph=nominal, scene=scene)) == augmented
    first, second = server.bodies()
    assert "recovery orchestration agent" in first["messages"][0]["content"]
    assert "Nominal task graph:" in first["messages"][1]["content"]
    assert '"id": "e6"' in first["messages"][1]["content"]
    assert "edges[4].actions: nominal edge 'e5' must keep its actions" in second["messages"][-1]["content"]
    assert llm.calls[0].agent == "arranger"


def test_arrange_online_repair_names_the_failure(server, augmented, scene):
    server.push(reply(augmented))
    failure = UnanticipatedFailure(edge="e5", context="v4", observation="bottle lies on its side")
    reasoner(server).arrange(ArrangeRequest(graph=augmented, scene=scene, failure=failure))
    user = server.bodies()[0]["messages"][1]["content"]
    assert "Online repair: edge 'e5'" in user and "bottle lies on its side" in user


def test_conduct_keeps_the_structure(server, augmented, scene):
    tuned = augmented.model_copy(deep=True)
    tuned.edges[1].failures[2].monitor = "drift(cup, 0.015)"
    dropped = augmented.model_copy(deep=True)
    dropped.edges = dropped.edges[:-1]
    server.push(reply(dropped), reply(tuned))
    llm = reasoner(server)
    assert llm.conduct(ConductRequest(graph=augmented, scene=scene)) == tuned
    assert "execution compilation agent" in server.bodies()[0]["messages"][0]["content"]
    missing = augmented.edges[-1].id
    assert f"must keep every edge of its input (missing: {missing})" in server.bodies()[1]["messages"][-1]["content"]


def test_wrong_request_type_is_refused(server, nominal, scene):
    with pytest.raises(TypeError, match="expected ArrangeRequest, got ComposeRequest"):
        reasoner(server).arrange(compose_request(nominal, scene))


def test_other_client_errors_become_transport_errors(nominal, scene):
    class Broken:
        class chat:  # mimics the client's attribute path
            class completions:
                @staticmethod
                def create(**kwargs):
                    raise openai.OpenAIError("unreadable response")

    config = LlmConfig(base_url="http://127.0.0.1:9/v1", model="m", api_key="k")
    llm = LlmReasoner(config, client=Broken())
    with pytest.raises(ReasonerTransportError, match="OpenAIError: unreadable response"):
        llm.compose(compose_request(nominal, scene))
    assert len(llm.calls) == 1 and not llm.calls[0].ok


@pytest.mark.parametrize("settings,problem", [
    ({"base_url": "ftp://example.org/v1"}, "base_url: expected an http:// or https:// URL with a host"),
    ({"base_url": "127.0.0.1:11434/v1"}, "base_url: expected an http:// or https:// URL with a host"),
    ({"timeout_s": 1e300}, "timeout_s: at most 86400 s (a day)"),
    ({"deadline_s": 1e9}, "deadline_s: at most 86400 s (a day)"),
])
def test_settings_an_endpoint_cannot_use_are_refused_when_read(settings, problem):
    # Before, an ftp:// or scheme-less URL was retried for ~15 s, and a huge timeout overflowed a clock.
    values = {"base_url": "http://127.0.0.1:1/v1", "model": "m", "api_key": "k", **settings}
    with pytest.raises(ReasonerConfigError) as caught:
        LlmConfig(**values)
    assert any(problem in line for line in caught.value.problems)


def test_credentials_in_the_base_url_are_never_printed_nor_recorded(scene, nominal):
    from agentchord.agents.llm.config import redact_url

    assert redact_url("http://user:s3cret@127.0.0.1:9/v1") == "http://***@127.0.0.1:9/v1"
    assert redact_url("https://api.openai.com/v1") == "https://api.openai.com/v1"
    config = LlmConfig(base_url="http://user:s3cret@127.0.0.1:9/v1", model="m", api_key="k", timeout_s=1.0, max_retries=0,
                       deadline_s=5.0)
    llm = LlmReasoner(config, sleep=lambda s: None)
    from agentchord.agents.exceptions import ReasonerError

    with pytest.raises(ReasonerError) as caught:
        llm.compose(compose_request(nominal, scene))
    assert "s3cret" not in str(caught.value) and "***@127.0.0.1:9" in str(caught.value)
    assert "s3cret" not in json.dumps(llm.calls[-1].to_trace_event())


@pytest.mark.parametrize(("url", "model", "message"), [
    ("http://[::1", "m", "base_url: not a URL (Invalid IPv6 URL)"),
    ("http://127.0.0.1:8000/v1\udcff", "m", "base_url: expected ASCII text"),
    ("http://127.0.0.1:8000/v1", "\udcff\udcfe", "model: expected ASCII text"),
    ("http://127.0.0.1:99999/v1", "m", "Port out of range"),
])
def test_llm_settings_that_no_request_can_carry_are_refused_up_front(url, model, message):
    """An adversarial pass (issue 58): these were internal errors (exit 3) at the first request."""
    from agentchord.agents.exceptions import ReasonerConfigError
    from agentchord.agents.llm.config import LlmConfig

    with pytest.raises(ReasonerConfigError, match=re.escape(message)):
        LlmConfig(base_url=url, model=model, api_key="k")
