"""The latency models: flat per kind, and priced by what a call writes."""

import pytest

from agentchord.execution.reasoning import (
    LatencyModel,
    ModelledCall,
    ReasoningConfig,
    TokenLatencyModel,
    latency_from_dict,
    parse_latency,
)


def test_a_call_is_priced_by_its_first_token_images_and_output():
    model = TokenLatencyModel()
    assert model.price(ModelledCall("composer", "plan", tokens=600)) == pytest.approx(0.45 + 600 / 120)
    vqa = ModelledCall("vqa", "vqa", tokens=20, images=1)
    assert model.price(vqa) == pytest.approx(0.45 + 0.9 + 20 / 120)
    assert model.price(vqa) == pytest.approx(LatencyModel().vqa, abs=0.05)  # the flat VQA constant, within 50 ms
    assert model.of("plan") == pytest.approx(0.45 + 800 / 120) == model.reference_plan_s
    faster = TokenLatencyModel(ttft_s=0.2, tokens_per_s=400.0, image_s=0.0)
    assert faster.price(ModelledCall("a", "vlm", tokens=400, images=3)) == pytest.approx(1.2)


def test_the_flat_model_ignores_what_a_call_writes():
    model = LatencyModel(plan=20.0)
    assert model.price(ModelledCall("composer", "plan", tokens=10)) == 20.0
    assert model.price(ModelledCall("composer", "plan", tokens=10_000)) == 20.0
    assert not model.streams and TokenLatencyModel.streams


def test_latency_option_selects_either_model_and_refuses_mixtures():
    assert parse_latency("plan=7,vqa=1.5") == LatencyModel(plan=7.0, vqa=1.5)
    assert parse_latency("tokens") == TokenLatencyModel()
    assert parse_latency("") == TokenLatencyModel()
    assert parse_latency("ttft=0.9,rate=80,concurrency=2") == TokenLatencyModel(ttft_s=0.9, tokens_per_s=80.0, concurrency=2)
    for bad in ("plan=7,rate=80", "rate=0", "rate=nan", "concurrency=1.5", "concurrency=0", "speed=3", "ttft", "image=-1"):
        with pytest.raises(ValueError):
            parse_latency(bad)


@pytest.mark.parametrize("model", [LatencyModel(plan=20.0), TokenLatencyModel(tokens_per_s=80.0, concurrency=2)])
def test_a_manifest_keeps_which_model_it_was(model):
    config = ReasoningConfig(latency=model, vqa_miss=0.1)
    assert ReasoningConfig.from_dict(config.to_dict()) == config
    # A manifest written before the token model had no name for it: flat.
    assert latency_from_dict({"plan": 7.0, "vqa": 1.5, "vlm": 3.5}) == LatencyModel()
