"""The add-on is unregistered when the tests end: the `bpy` module (4.2) crashes at the
interpreter's exit while any add-on class or menu entry is still registered."""

import pytest

import scene_tools


@pytest.fixture(scope="session", autouse=True)
def unregister_at_the_end():
    yield
    scene_tools.unregister()
