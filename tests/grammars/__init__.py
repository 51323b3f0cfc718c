"""Third-party grammars, and the parsers generated from them, for the tests (README.md)."""
