"""The package's surface: version, documentation, enumerations against the library."""

import pydoc

import fcm


def test_version():
    assert fcm.__version__ == fcm._fcm.version == fcm._fcm.header_version
    assert all(part.isdigit() for part in fcm.__version__.split("."))


def test_docstrings():
    for name in fcm.__all__:
        obj = getattr(fcm, name)
        if isinstance(obj, type):
            assert obj.__doc__ and len(obj.__doc__) > 20, name
    text = pydoc.render_doc(fcm.CellRules, renderer=pydoc.plaintext)
    for option in fcm.CellRules.defaults():
        assert option in text, option  # every option is documented
    text = pydoc.render_doc(fcm.Integrator, renderer=pydoc.plaintext)
    for option in fcm.Integrator.defaults():
        assert option in text, option


def test_status_names_match_the_library():
    names = [fcm._fcm.status_name(int(st)) for st in fcm.Status]
    assert len(set(names)) == len(names) and names[0] == "success"
    assert fcm._fcm.status_name(int(fcm.Status.ERR_ARG)) == "invalid argument"
    assert fcm._fcm.status_name(int(fcm.Status.ERR_IO)) == "input/output error"
    assert fcm._fcm.status_name(int(fcm.Status.ERR_INTERNAL)) == "internal error"
    assert fcm.Error.__mro__[1] is RuntimeError
