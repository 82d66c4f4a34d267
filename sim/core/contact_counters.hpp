// What contact did over a step or over a run: counts and times that add up. The contact stage
// reports them per step, the integrator adds its own times, and the application sums them into
// the run's totals (summary.json, the checkpoint) and writes them per step (stats.csv), each with
// `+=`. A new counter is a member here, a line in operator+=, and a column or key where it is
// written.
#pragma once

namespace clothsim {

struct ContactCounters {
  long long pairs_tested = 0;             // narrow-phase pairs (point–triangle, edge–edge) examined
  long long impulses = 0;                 // pairs given a normal impulse, plus friction impulses applied
  long long impact_zones = 0;             // zones the fail-safe moved as one
  long long unresolved = 0;               // pairs still colliding when the fail-safe gave up (should be 0)
  long long response_iterations = 0;      // augmented-Lagrangian updates of the implicit response
  long long response_cg_iterations = 0;   // conjugate-gradient iterations in them
  long long response_factorizations = 0;  // factorisations of the response's Newton matrix
  long long newton_iterations = 0;        // linear solves of the step with the contact potential in them
  long long relinearisations = 0;         // steps solved again with the elastic terms re-linearised at
                                          // their end positions (rotations that turned within the step)
  double ms = 0.0;                        // all of contact's time [ms]; of it:
  double broad_ms = 0.0, narrow_ms = 0.0, response_ms = 0.0;  // the fail-safe's phases [ms]
  double potential_ms = 0.0;              // the contact potential inside the step [ms]; of it:
  double candidates_ms = 0.0;             //   its candidate search (broad phases) [ms]
  double line_search_ms = 0.0;            //   the CCD step bounds on Newton's moves [ms]
  double failsafe_ms = 0.0;               // the fail-safe after the step (filter), part of ms [ms]
  // Not part of ms (booked as the solve): the linear solves of steps where the potential acted,
  // the step's first solve and Newton's further solves apart [ms].
  double first_solve_ms = 0.0, newton_solve_ms = 0.0;
  long long contact_steps = 0;            // steps in which contact acted (a pair active, friction,
                                          // or a fail-safe impulse)
  double contact_step_ms = 0.0;           // their whole time [ms]
  double free_step_ms = 0.0;              // the whole time of the other steps [ms]

  // The barrier's own evaluations: potential_ms less its candidate search and line search [ms].
  double barrier_evaluation_ms() const { return potential_ms - line_search_ms - candidates_ms; }

  ContactCounters& operator+=(const ContactCounters& o) {
    pairs_tested += o.pairs_tested;
    impulses += o.impulses;
    impact_zones += o.impact_zones;
    unresolved += o.unresolved;
    response_iterations += o.response_iterations;
    response_cg_iterations += o.response_cg_iterations;
    response_factorizations += o.response_factorizations;
    newton_iterations += o.newton_iterations;
    relinearisations += o.relinearisations;
    ms += o.ms;
    broad_ms += o.broad_ms;
    narrow_ms += o.narrow_ms;
    response_ms += o.response_ms;
    potential_ms += o.potential_ms;
    candidates_ms += o.candidates_ms;
    line_search_ms += o.line_search_ms;
    failsafe_ms += o.failsafe_ms;
    first_solve_ms += o.first_solve_ms;
    newton_solve_ms += o.newton_solve_ms;
    contact_steps += o.contact_steps;
    contact_step_ms += o.contact_step_ms;
    free_step_ms += o.free_step_ms;
    return *this;
  }
};

}  // namespace clothsim
