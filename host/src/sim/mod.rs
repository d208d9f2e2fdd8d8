//! Everything on the host that runs the simulated target in process (`pushbot_sim`): the
//! in-process driver of the link client, and the in-process robot of the strategy code with
//! its truth-with-noise "camera". No other module of the link or robot layers imports the
//! simulator.

pub mod inprocess;
pub mod robot;
