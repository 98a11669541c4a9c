fn main() {}

mbs::multibody! {
    model Cart {
        dof x = 0.1;
        body cart { mass = 1.0; }
        TOG[cart] = Tdisp(1 + x, 0, 0);
        spring(ground, cart, k = 10.0, l0 = 1.0, axis = w);
        damper(ground, cart, c = 0.5, axis = (1, 1, 0));
    }
}
