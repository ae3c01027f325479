# SPDX-License-Identifier: BSD-3-Clause
"""The exceptions the module raises: Error for every failure the library reports, and
ArgumentError (an Error and a ValueError) for an argument out of range."""
from . import _structs as S
from ._library import lib


class Error(RuntimeError):
    """A libisoprop failure: `status` is the library's ip_status (a negative int),
    `status_name` its short description, and str(e) the library's one-line message, which
    starts with the file (or object) and says what is wrong."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status
        self.status_name = lib.ip_status_message(status).decode()
        self.message = message


IP_ERR_ARGUMENT = -3  # include/isoprop/status.h


class ArgumentError(Error, ValueError):
    """An argument out of range, refused before any work: a ValueError, and an isoprop.Error
    (status IP_ERR_ARGUMENT unless the library's check said otherwise) since the library
    refused such values itself before the module checked them. str(e) starts with the
    argument's name and says what is allowed."""

    def __init__(self, message: str, status: int = IP_ERR_ARGUMENT) -> None:
        super().__init__(status, message)


def new_error() -> S.Error:
    """A cleared ip_error for one call."""
    return S.Error()


def check(status: int, err: S.Error) -> None:
    """Raises Error when `status` (an ip_status) is not IP_OK, with err's message."""
    if status != 0:
        message = err.message.decode("utf-8", "replace") or lib.ip_status_message(status).decode()
        raise Error(status, message)
