import threading

import pytest

import engine.gpu.context as gc


def test_session_is_reentrant_and_thread_safe(gpu):
    with gc.gpu_session() as ctx:
        with gc.gpu_session() as inner:
            assert inner is ctx is gc.gpu_context()
    seen = []

    def work():
        with gc.gpu_session() as c:
            buf = c.buffer(b"\x01\x02\x03\x04")
            seen.append(buf.read())
            buf.release()

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert seen == [b"\x01\x02\x03\x04"] * 4


def test_missing_egl_gives_a_clear_error(monkeypatch):
    import moderngl

    def fail(**kwargs):
        raise RuntimeError("eglGetDisplay failed")

    monkeypatch.setattr(gc, "_STATE", {"ctx": None, "error": None})
    monkeypatch.setattr(moderngl, "create_standalone_context", fail)
    with pytest.raises(gc.GpuUnavailable, match="EGL.*eglGetDisplay failed"):
        gc.gpu_context()
    assert not gc.gpu_available()  # remembered, fails fast
    with pytest.raises(gc.GpuUnavailable):
        with gc.gpu_session():
            pass


def test_context_does_not_become_moderngl_default(gpu):
    import moderngl

    assert getattr(moderngl, "_store").default_context is not gpu
