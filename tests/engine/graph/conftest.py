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


@register
class _Slow(NodeType):
    type_name = "_TestSlow"
    code = "slow"
    outputs = (Port("value", "Field"),)
    params = (Param("seconds", "float", 5.0, 0.0, 60.0),)

    def evaluate(self, inputs, params, ctx):
        CALLS[ctx.node_id] += 1
        t0 = time.perf_counter()
        steps = 0
        while time.perf_counter() - t0 < params["seconds"]:
            time.sleep(0.01)
            steps += 1
            if not ctx.progress(time.perf_counter() - t0, params["seconds"]):
                ctx.check()
        return {"value": float(steps)}


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
