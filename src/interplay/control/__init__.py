"""Control of active figures: PD servo gains (pd), state machines (fsm), behaviours."""
