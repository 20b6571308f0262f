"""Built-in robot models (the zoo)."""
