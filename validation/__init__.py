"""jaxcable's validations against independent references; run them from the repository's
root with `python -m validation` (see `validation/README.md`). Not part of the package."""
