"""The one exception family the CLI turns into a single line and exit code 2."""


class JacgenError(Exception):
    """Invalid input or usage: printed as one line, never as a traceback."""


class RobotFileError(JacgenError):
    """A mistake in a robot file, located by file, line, column and key path."""

    def __init__(self, path: str, line: int, column: int, key: str, message: str):
        self.path, self.line, self.column, self.key, self.message = path, line, column, key, message
        where = f"{path}:{line}:{column}"
        super().__init__(f"{where}: {key}: {message}" if key else f"{where}: {message}")

    def __reduce__(self):
        """Pickled by its parts (a worker process sends it back, `parallel`)."""
        return type(self), (self.path, self.line, self.column, self.key, self.message)
