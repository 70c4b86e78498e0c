"""The textbook side: Konoplev's S·Θ·Sᵀ algorithm (book chapter 4). Never imports Pinocchio."""
