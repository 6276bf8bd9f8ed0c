// Where order-functions.mjs files a function: by the first two parts of
// its path, a trait's function by the type it is for (or the trait's, for
// a type parameter, tuple or slice), without the hash and generics.

import assert from 'node:assert/strict';
import test from 'node:test';
import { owner } from './order-functions.mjs';

test('a function is filed under the first two parts of its path, a trait impl under its type', () => {
  const cases = [
    ['plm_console::stores::Console::apply::h97b81f449a8ad990', 'plm_console::stores'],
    ['core::ptr::drop_in_place<plm_console::street::Lamp>::h4cfd82dfd33ccab5', 'core::ptr'],
    ['<plm_console::transport::sim::SimTransport as plm_console::transport::Transport>::poll::h62b5c11a1892523c', 'plm_console::transport'],
    ['<&T as core::fmt::Display>::fmt::h9e3229f69738bbd7', 'core::fmt'],
    ['<T as tachys::view::any_view::IntoAny>::into_any::build::hb399d60bf44ac0d9', 'tachys::view'],
    ['<(A,B) as tachys::html::attribute::NextAttribute>::add_any_attr::h0f7e112fefe18bad', 'tachys::html'],
    ['<alloc::vec::Vec<T,A> as core::ops::drop::Drop>::drop::h1', 'alloc::vec'],
    ['main', 'main'],
  ];
  for (const [name, expected] of cases) assert.equal(owner(name), expected, name);
});
