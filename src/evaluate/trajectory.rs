//! A run's typed trajectory as a table (issue 37 item 5): the evaluator hands the closed loop's
//! [`Trajectory`] on typed; the files that hold it (`trajectory_best.csv`, a `simulate`'s
//! `timeseries`) are written from this table.

use crate::report::{Result, Table};
use crate::scenario::channels::Trajectory;

/// A table of a run's trajectory: one f64 column per channel, named by
/// [`crate::scenario::channels::Channel::name`] (SI units, the channel's frame), in the
/// trajectory's column order.
pub fn trajectory_table(traj: &Trajectory) -> Result<Table> {
    let mut t = Table::new();
    for (c, x) in traj.iter() {
        t.push(c.name(), x.to_vec())?;
    }
    Ok(t)
}
