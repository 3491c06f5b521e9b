"""The Schneider Electric C-60 circuit-breaker mechanism: model, bench tests, CAD primitives."""
