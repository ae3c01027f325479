"""The exception the module raises for every failure the library reports."""
from . import _structs as S
from ._library import lib


class Error(RuntimeError):
    """A libisoprop failure: `status` is the library's ip_status (a negative int),
    `status_name` its short description, and str(e) the library's one-line message, which
    starts with the file (or object) and says what is wrong."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status
        self.status_name = lib.ip_status_message(status).decode()
        self.message = message


def new_error():
    """A cleared ip_error for one call."""
    return S.Error()


def check(status, err):
    """Raises Error when `status` (an ip_status) is not IP_OK, with err's message."""
    if status != 0:
        message = err.message.decode("utf-8", "replace") or lib.ip_status_message(status).decode()
        raise Error(status, message)
