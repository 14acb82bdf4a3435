"""Small test-only node types: counting calls lets tests see what re-ran."""

from __future__ import annotations

import time
from collections import Counter

import pytest

from engine.graph import NodeType, Param, Port, register

CALLS: Counter = Counter()


@register
class _Number(NodeType):
    type_name = "_TestNumber"
    code = "num"
    outputs = (Port("value", "Field"),)
    params = (Param("value", "float", 1.0, -100.0, 100.0),)

    def evaluate(self, inputs, params, ctx):
        CALLS[ctx.node_id] += 1
        return {"value": params["value"]}


@register
class _Sum(NodeType):
    type_name = "_TestSum"
    code = "sum"
    inputs = (Port("terms", "Field", multi=True),)
    outputs = (Port("value", "Field"),)
    params = (Param("scale", "float", 1.0, -100.0, 100.0),)

    def evaluate(self, inputs, params, ctx):
        CALLS[ctx.node_id] += 1
        return {"value": params["scale"] * sum(inputs["terms"])}


@register
class _Fail(NodeType):
    type_name = "_TestFail"
    code = "fail"
    inputs = (Port("x", "Field"),)
    outputs = (Port("value", "Field"),)
    params = (Param("fail", "bool", True),)

    def evaluate(self, inputs, params, ctx):
        CALLS[ctx.node_id] += 1
        if params["fail"]:
            raise ValueError("deliberate failure")
        return {"value": inputs["x"]}


# What the slow node saw: its progress checks, and those made after the test
# asked for a cancel (set SLOW["cancel_requested"] just before cancelling).
SLOW: dict = {}


@register
class _Slow(NodeType):
    """Makes `steps` progress checks, 10 ms apart; counts them in SLOW."""

    type_name = "_TestSlow"
    code = "slow"
    outputs = (Port("value", "Field"),)
    params = (Param("steps", "int", 500, 1, 100_000),)

    def evaluate(self, inputs, params, ctx):
        CALLS[ctx.node_id] += 1
        SLOW.update(checks=0, checks_after_cancel=0)
        for step in range(params["steps"]):
            time.sleep(0.01)
            SLOW["checks"] += 1
            if SLOW.get("cancel_requested"):
                SLOW["checks_after_cancel"] += 1
            if not ctx.progress(step + 1, params["steps"]):
                ctx.check()
        return {"value": float(params["steps"])}


@register
class _Random(NodeType):
    type_name = "_TestRandom"
    code = "rnd"
    uses_rng = True
    outputs = (Port("value", "Field"),)

    def evaluate(self, inputs, params, ctx):
        return {"value": float(ctx.rng.random())}


@pytest.fixture(autouse=True)
def _reset_calls():
    CALLS.clear()
    yield
