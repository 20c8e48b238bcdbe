//! Forces, symmetries and the stepper.
